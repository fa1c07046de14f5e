//! Complex wrinkle fields (dissertation ch. 3).
