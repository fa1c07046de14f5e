//! Typed element ids of a [`HalfEdgeMesh`](super::HalfEdgeMesh) and per-element containers
//! indexable only by their own id type (in the spirit of geometry-central's `VertexData<T>`), so
//! indexing per-face data with a vertex id is a type error.
//!
//! Every id is a `u32` index (`#[repr(transparent)]`); `INVALID` (`u32::MAX`) means "none".
//! The two halves of edge `e` are half-edges `2e` and `2e + 1`: [`HalfedgeId::twin`] is the only
//! place in the crate that flips the low bit, and [`HalfedgeId::edge`] /
//! [`EdgeId::halfedge`] the only places that shift.

use std::fmt;
use std::marker::PhantomData;
use std::ops::{Index, IndexMut};

/// Behaviour shared by the id types: conversion to and from the raw `u32` index.
pub trait ElementId: Copy + Eq + Ord + fmt::Debug {
    /// The id with index `i`.
    fn from_raw(i: u32) -> Self;
    /// The raw index.
    fn raw(self) -> u32;
}

macro_rules! id_type {
    ($(#[$doc:meta])* $name:ident, $kind:literal) => {
        $(#[$doc])*
        #[repr(transparent)]
        #[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub struct $name(u32);

        impl $name {
            /// "No element" (`u32::MAX`).
            pub const INVALID: $name = $name(u32::MAX);

            /// The id with index `i`.
            #[inline]
            pub const fn new(i: u32) -> $name {
                $name(i)
            }

            /// The raw index.
            #[inline]
            pub const fn raw(self) -> u32 {
                self.0
            }

            /// The raw index as `usize`.
            #[inline]
            pub const fn index(self) -> usize {
                self.0 as usize
            }

            /// True unless this is [`Self::INVALID`].
            #[inline]
            pub const fn is_valid(self) -> bool {
                self.0 != u32::MAX
            }

            /// The raw indices of `ids`, without copying (for index-based boundaries such as
            /// the BVH).
            #[inline]
            pub fn raw_slice(ids: &[$name]) -> &[u32] {
                // SAFETY: `$name` is `#[repr(transparent)]` over `u32`, so `[$name]` and
                // `[u32]` have the same layout, and the lifetime is carried over.
                unsafe { std::slice::from_raw_parts(ids.as_ptr().cast::<u32>(), ids.len()) }
            }
        }

        impl ElementId for $name {
            #[inline]
            fn from_raw(i: u32) -> Self {
                $name(i)
            }
            #[inline]
            fn raw(self) -> u32 {
                self.0
            }
        }

        impl fmt::Debug for $name {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                if self.is_valid() {
                    write!(f, concat!($kind, "{}"), self.0)
                } else {
                    f.write_str(concat!($kind, "INVALID"))
                }
            }
        }

        impl fmt::Display for $name {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                fmt::Display::fmt(&self.0, f)
            }
        }

        impl From<$name> for u32 {
            #[inline]
            fn from(id: $name) -> u32 {
                id.0
            }
        }
    };
}

id_type!(
    /// A vertex of a half-edge mesh.
    VertexId,
    "v"
);
id_type!(
    /// A face of a half-edge mesh.
    FaceId,
    "f"
);
id_type!(
    /// An (undirected) edge of a half-edge mesh: half-edges `2e` and `2e + 1`.
    EdgeId,
    "e"
);
id_type!(
    /// A half-edge of a half-edge mesh.
    HalfedgeId,
    "h"
);

impl HalfedgeId {
    /// The opposite half-edge of the same edge (`2e ↔ 2e + 1`). Never fails; the twin of
    /// [`HalfedgeId::INVALID`] is not meaningful.
    #[inline]
    pub const fn twin(self) -> HalfedgeId {
        HalfedgeId(self.0 ^ 1)
    }

    /// The edge this half-edge belongs to.
    #[inline]
    pub const fn edge(self) -> EdgeId {
        EdgeId(self.0 >> 1)
    }
}

impl EdgeId {
    /// The first half-edge `2e` of the edge (its twin is `2e + 1`).
    #[inline]
    pub const fn halfedge(self) -> HalfedgeId {
        HalfedgeId(self.0 << 1)
    }
}

/// A `Vec<T>` indexed by one id type `I` only.
#[derive(Clone, PartialEq, Eq)]
pub struct IdVec<I, T> {
    data: Vec<T>,
    _id: PhantomData<fn(I) -> I>,
}

/// Per-vertex data, indexed by [`VertexId`].
pub type VertexData<T> = IdVec<VertexId, T>;
/// Per-face data, indexed by [`FaceId`].
pub type FaceData<T> = IdVec<FaceId, T>;
/// Per-edge data, indexed by [`EdgeId`].
pub type EdgeData<T> = IdVec<EdgeId, T>;
/// Per-half-edge data, indexed by [`HalfedgeId`].
pub type HalfedgeData<T> = IdVec<HalfedgeId, T>;

impl<I: ElementId, T> IdVec<I, T> {
    /// An empty container.
    pub fn new() -> Self {
        IdVec {
            data: Vec::new(),
            _id: PhantomData,
        }
    }

    /// `len` copies of `value` (ids `0..len`).
    pub fn filled(len: usize, value: T) -> Self
    where
        T: Clone,
    {
        Self::from_vec(vec![value; len])
    }

    /// The container whose element `i` is `data[i]`.
    pub fn from_vec(data: Vec<T>) -> Self {
        IdVec {
            data,
            _id: PhantomData,
        }
    }

    /// Number of slots.
    #[inline]
    pub fn len(&self) -> usize {
        self.data.len()
    }

    /// True when there is no slot.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    /// Element `id`, `None` when out of range.
    #[inline]
    pub fn get(&self, id: I) -> Option<&T> {
        self.data.get(id.raw() as usize)
    }

    /// Appends an element and returns its id.
    pub fn push(&mut self, value: T) -> I {
        let id = I::from_raw(self.data.len() as u32);
        self.data.push(value);
        id
    }

    /// The elements in id order.
    #[inline]
    pub fn as_slice(&self) -> &[T] {
        &self.data
    }

    /// The elements in id order, mutable.
    #[inline]
    pub fn as_mut_slice(&mut self) -> &mut [T] {
        &mut self.data
    }

    /// The ids `0..len()`.
    pub fn ids(&self) -> impl Iterator<Item = I> {
        (0..self.data.len() as u32).map(I::from_raw)
    }

    /// `(id, element)` pairs in id order.
    pub fn iter(&self) -> impl Iterator<Item = (I, &T)> {
        self.data
            .iter()
            .enumerate()
            .map(|(i, x)| (I::from_raw(i as u32), x))
    }

    /// Sets every slot to `value`.
    pub fn fill(&mut self, value: T)
    where
        T: Clone,
    {
        self.data.fill(value);
    }

    /// Grows or shrinks to `len` slots, filling new ones with `value`.
    pub fn resize(&mut self, len: usize, value: T)
    where
        T: Clone,
    {
        self.data.resize(len, value);
    }

    /// Keeps the first `len` slots.
    pub fn truncate(&mut self, len: usize) {
        self.data.truncate(len);
    }

    /// Consumes the container and returns its elements in id order.
    pub fn into_vec(self) -> Vec<T> {
        self.data
    }
}

impl<I: ElementId, T> Default for IdVec<I, T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<I: ElementId, T: fmt::Debug> fmt::Debug for IdVec<I, T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_list().entries(&self.data).finish()
    }
}

/// The container whose element `i` is `data[i]`.
impl<I: ElementId, T> From<Vec<T>> for IdVec<I, T> {
    fn from(data: Vec<T>) -> Self {
        Self::from_vec(data)
    }
}

/// Collects elements in id order (the first gets id 0).
impl<I: ElementId, T> FromIterator<T> for IdVec<I, T> {
    fn from_iter<It: IntoIterator<Item = T>>(iter: It) -> Self {
        Self::from_vec(iter.into_iter().collect())
    }
}

impl<I: ElementId, T> Index<I> for IdVec<I, T> {
    type Output = T;
    #[inline]
    #[track_caller]
    fn index(&self, id: I) -> &T {
        &self.data[id.raw() as usize]
    }
}

impl<I: ElementId, T> IndexMut<I> for IdVec<I, T> {
    #[inline]
    #[track_caller]
    fn index_mut(&mut self, id: I) -> &mut T {
        &mut self.data[id.raw() as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn twins_edges_and_containers() {
        let h = HalfedgeId::new(7);
        assert_eq!(h.twin(), HalfedgeId::new(6));
        assert_eq!(h.twin().twin(), h);
        assert_eq!(h.edge(), EdgeId::new(3));
        assert_eq!(h.edge().halfedge(), HalfedgeId::new(6));
        assert!(!VertexId::INVALID.is_valid());
        assert_eq!(format!("{:?}", FaceId::new(2)), "f2");
        let mut d: VertexData<f64> = VertexData::filled(3, 0.5);
        let v = d.push(2.0);
        d[VertexId::new(1)] = 1.0;
        assert_eq!(v, VertexId::new(3));
        assert_eq!(d.as_slice(), &[0.5, 1.0, 0.5, 2.0]);
        assert_eq!(d.ids().last(), Some(VertexId::new(3)));
    }
}
