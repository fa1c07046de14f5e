//! Tension-field wrinkles (dissertation ch. 2).
