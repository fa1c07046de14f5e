//! Low-poly meshes by screen size (dissertation ch. 4).
