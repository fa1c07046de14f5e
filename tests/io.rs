//! Mesh file I/O tests.
#[test]
fn placeholder() {}
