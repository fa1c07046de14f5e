//! Cages that strictly enclose the input (dissertation ch. 4.5.2).
