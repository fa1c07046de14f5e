//! The C boundary's vocabulary: the one way an export checks its arguments, reads versioned
//! structs and hands results back (in the manner of rustls-ffi's `try_ref_from_ptr!` and
//! `Castable`).
//!
//! Every fallible export is `guard(|| ...)` or `guard_progress(cb, user_data, |relay| ...)`
//! (see `common`: panic fence, thread pool, status mapping, last-error message) around a few
//! lines that use the helpers here. Each helper fails with `Error::InvalidArgument` naming the
//! C parameter, so the message tells the caller which argument is wrong:
//!
//! - pointers: [`arg_ref`] (a borrowed input or handle), [`non_null`], [`arg_out`] (a checked output slot
//!   written only at the end, so nothing is written on failure), [`arg_slice`];
//! - numbers: [`finite_slice`], [`check_f64`], [`check_range`], [`check_flags`], [`bool_field`];
//! - versioned structs (leading `uint32_t struct_size`): [`read_versioned`] for parameters,
//!   [`versioned_out`] / [`VersionedOut`] for stats and reports filled up to the caller's size;
//! - handles: [`destroy`] (NULL accepted, panics contained), [`guard_value`] for queries that
//!   answer a number instead of a status;
//! - capabilities: the `requires!` macro answers `PLEAT_STATUS_UNSUPPORTED` in builds without
//!   the cargo feature an export needs.
//!
//! This module imports only `crate::Error` and `ffi::common`.

// Builds without a capability leave some helpers unused.
#![cfg_attr(not(all(feature = "lod", feature = "wrinkle")), allow(dead_code))]

use super::common::null_arg;
use crate::{Error, Result};
use std::panic::{catch_unwind, AssertUnwindSafe};

/// Runs `$body` (a `PleatStatus` expression) when built with the cargo feature `$feature`;
/// otherwise returns `PLEAT_STATUS_UNSUPPORTED` with the one "compiled without" message and
/// marks the listed parameters used.
macro_rules! requires {
    ($feature:tt, [$($arg:expr),*], $body:expr) => {{
        #[cfg(feature = $feature)]
        {
            $body
        }
        #[cfg(not(feature = $feature))]
        {
            let _ = ($($arg,)*);
            $crate::ffi::common::unsupported($feature)
        }
    }};
}
pub(crate) use requires;

/// Implements [`Versioned`] for a struct (`versioned!(Type, min_size)`), and
/// [`VersionedParams`] too when its `*_default()` function is named
/// (`versioned!(Type, min_size, default_fn)`).
macro_rules! versioned {
    ($t:ident, $min:literal $(, $default:ident)?) => {
        // SAFETY: repr(C), leading `struct_size: u32`, integer and real fields only.
        unsafe impl $crate::ffi::boundary::Versioned for $t {
            const NAME: &'static str = stringify!($t);
            const MIN_SIZE: u32 = $min;
        }
        $(impl $crate::ffi::boundary::VersionedParams for $t {
            const DEFAULT_FN: &'static str = stringify!($default);
            fn defaults() -> Self {
                $default()
            }
        })?
    };
}
pub(crate) use versioned;

// ---------------------------------------------------------------------------------------------
// Pointers

/// Borrows the input (or handle) `p`; `Err(InvalidArgument)` "`name` is NULL" when NULL.
///
/// # Safety
/// `p` is NULL or valid for reads of a `T` for `'a`.
pub(crate) unsafe fn arg_ref<'a, T>(p: *const T, name: &str) -> Result<&'a T> {
    p.as_ref().ok_or_else(|| null_arg(name))
}

/// `Err(InvalidArgument)` "`name` is NULL" when `p` is NULL (for pointers read or written
/// later, e.g. after a size check).
pub(crate) fn non_null<T>(p: *const T, name: &str) -> Result<()> {
    if p.is_null() {
        return Err(null_arg(name));
    }
    Ok(())
}

/// Borrows `len` caller values at `p`; NULL fails (whatever `len`), naming `name`.
///
/// # Safety
/// `p` is NULL or valid for reads of `len` values of `T`.
pub(crate) unsafe fn arg_slice<'a, T>(p: *const T, len: usize, name: &str) -> Result<&'a [T]> {
    if p.is_null() {
        return Err(null_arg(name));
    }
    if len
        .checked_mul(std::mem::size_of::<T>())
        .is_none_or(|b| b > isize::MAX as usize)
    {
        return Err(Error::InvalidArgument(format!(
            "`{name}` cannot hold {len} values"
        )));
    }
    Ok(std::slice::from_raw_parts(p, len))
}

/// A caller's output pointer checked non-NULL. Written once, by [`Out::put`], after all the
/// fallible work, so that no output is written on failure.
pub(crate) struct Out<T>(*mut T);

/// Checks the output pointer `p` (`Err(InvalidArgument)` naming `name` when NULL).
///
/// # Safety
/// `p` is NULL or valid for a write of a `T` until the export returns.
pub(crate) unsafe fn arg_out<T>(p: *mut T, name: &str) -> Result<Out<T>> {
    if p.is_null() {
        return Err(null_arg(name));
    }
    Ok(Out(p))
}

impl<T> Out<T> {
    /// Writes `v` to the caller's slot (no drop of the old content: it is caller memory).
    pub(crate) fn put(self, v: T) {
        // SAFETY: non-NULL, and valid for a write by the contract of `arg_out`.
        unsafe { self.0.write(v) }
    }

    /// The slot `i` elements further on (for output arrays).
    ///
    /// # Safety
    /// The caller's array holds more than `i` elements.
    pub(crate) unsafe fn add(&self, i: usize) -> Out<T> {
        Out(self.0.add(i))
    }
}

impl<H> Out<*mut H> {
    /// Moves `v` into a new heap handle (freed by the matching `*_destroy`) and writes it.
    pub(crate) fn put_boxed(self, v: H) {
        self.put(Box::into_raw(Box::new(v)));
    }
}

/// Destroys a handle made by [`Out::put_boxed`]: NULL is ignored, a panic in a destructor is
/// contained.
///
/// # Safety
/// `p` is NULL or a handle from pleat not yet destroyed.
pub(crate) unsafe fn destroy<H>(p: *mut H) {
    if !p.is_null() {
        let _ = catch_unwind(AssertUnwindSafe(|| drop(Box::from_raw(p))));
    }
}

/// The fence of exports that answer a value instead of a status (lives with the other fences
/// in `common`, which must not import this module).
pub(crate) use super::common::guard_value;

// ---------------------------------------------------------------------------------------------
// Numbers

/// `Err(InvalidArgument)` "`{name}[i]` is v (NaN or infinite)" for the first non-finite value.
pub(crate) fn finite_slice(s: &[f64], name: &str) -> Result<()> {
    match s.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(Error::InvalidArgument(format!(
            "{name}[{i}] is {} (NaN or infinite)",
            s[i]
        ))),
        None => Ok(()),
    }
}

/// Checks a real parameter: `ok` is the whole condition (NaN must fail it); the message is
/// "`name` is v; must be `requirement`".
pub(crate) fn check_f64(v: f64, ok: bool, name: &str, requirement: &str) -> Result<()> {
    if ok {
        Ok(())
    } else {
        Err(Error::InvalidArgument(format!(
            "{name} is {v}; must be {requirement}"
        )))
    }
}

/// Checks an integer parameter against `lo..=hi`: "`name` is v; allowed lo to hi".
pub(crate) fn check_range(v: u32, lo: u32, hi: u32, name: &str) -> Result<()> {
    if (lo..=hi).contains(&v) {
        Ok(())
    } else {
        Err(Error::InvalidArgument(format!(
            "{name} is {v}; allowed {lo} to {hi}"
        )))
    }
}

/// Checks a bit set against the `known` bits: "`name` has unknown bits 0x..".
pub(crate) fn check_flags(flags: u32, known: u32, name: &str) -> Result<()> {
    match flags & !known {
        0 => Ok(()),
        bits => Err(Error::InvalidArgument(format!(
            "{name} has unknown bits {bits:#x}"
        ))),
    }
}

/// A `uint32_t` yes/no field: 0 or 1, else "`name` must be 0 or 1, got v".
pub(crate) fn bool_field(v: u32, name: &str) -> Result<bool> {
    match v {
        0 => Ok(false),
        1 => Ok(true),
        _ => Err(Error::InvalidArgument(format!(
            "{name} must be 0 or 1, got {v}"
        ))),
    }
}

// ---------------------------------------------------------------------------------------------
// Versioned structs

/// A C struct versioned by a leading `uint32_t struct_size`: the caller sets it to the size it
/// was compiled with, pleat reads or fills only that many bytes, so fields can be appended
/// without breaking older callers.
///
/// # Safety
/// Implementors are `#[repr(C)]`, start with a `u32` field `struct_size`, and every bit pattern
/// of their bytes is a valid value (integers, reals and arrays of them only).
pub(crate) unsafe trait Versioned: Copy {
    /// The C type name, for messages.
    const NAME: &'static str;
    /// The smallest `struct_size` accepted: the size of the struct's first published version.
    const MIN_SIZE: u32;
}

/// A versioned parameters struct with defaults taken from the Rust parameters' `Default`.
pub(crate) trait VersionedParams: Versioned {
    /// The C function that returns [`VersionedParams::defaults`], for messages.
    const DEFAULT_FN: &'static str;
    /// The defaults, with `struct_size = sizeof(Self)`.
    fn defaults() -> Self;
}

/// `size_of::<T>()` as a `struct_size` value.
pub(crate) fn full_size<T>() -> u32 {
    std::mem::size_of::<T>() as u32
}

/// Reads the caller's `struct_size`, checking it against `T::MIN_SIZE` (one message format for
/// every struct; `hint` ends it).
///
/// # Safety
/// `p` is non-NULL with 4 readable bytes.
unsafe fn checked_size<T: Versioned>(p: *const T, param: &str, hint: &str) -> Result<usize> {
    let size = std::ptr::read_unaligned(p as *const u32);
    if size < T::MIN_SIZE {
        return Err(Error::InvalidArgument(format!(
            "{param}->struct_size is {size} (at least {} is needed); set it to sizeof({}){hint}",
            T::MIN_SIZE,
            T::NAME
        )));
    }
    Ok(size as usize)
}

/// Reads a caller's versioned parameters: NULL gives `T::defaults()`; otherwise the first
/// `min(struct_size, sizeof(T))` bytes come from the caller and the rest keep their defaults.
/// The result's `struct_size` is `sizeof(T)`.
///
/// # Safety
/// `p` is NULL or points to `p->struct_size` readable bytes.
pub(crate) unsafe fn read_versioned<T: VersionedParams>(p: *const T, param: &str) -> Result<T> {
    let mut v = T::defaults();
    if p.is_null() {
        return Ok(v);
    }
    let hint = format!(", e.g. with {}()", T::DEFAULT_FN);
    let n = checked_size(p, param, &hint)?.min(std::mem::size_of::<T>());
    std::ptr::copy_nonoverlapping(p as *const u8, &mut v as *mut T as *mut u8, n);
    std::ptr::write_unaligned(&mut v as *mut T as *mut u32, full_size::<T>());
    Ok(v)
}

/// A caller's versioned output (a stats struct or an array of them), its size checked before
/// the work; [`VersionedOut::write`] fills it after.
pub(crate) struct VersionedOut<T> {
    ptr: *mut T,
    /// The caller's `struct_size`: the stride of an array of them.
    stride: usize,
}

/// Checks a versioned output: `Ok(None)` for NULL (the output is optional), else its
/// `struct_size` against `T::MIN_SIZE`.
///
/// # Safety
/// `p` is NULL or points to `p->struct_size` writable bytes (times the array length used).
pub(crate) unsafe fn versioned_out<T: Versioned>(
    p: *mut T,
    param: &str,
) -> Result<Option<VersionedOut<T>>> {
    if p.is_null() {
        return Ok(None);
    }
    let stride = checked_size(p, param, "")?;
    Ok(Some(VersionedOut { ptr: p, stride }))
}

/// As [`versioned_out`] for an output that must be given ("`param` is NULL" otherwise).
///
/// # Safety
/// As [`versioned_out`].
pub(crate) unsafe fn required_versioned_out<T: Versioned>(
    p: *mut T,
    param: &str,
) -> Result<VersionedOut<T>> {
    versioned_out(p, param)?.ok_or_else(|| null_arg(param))
}

impl<T: Versioned> VersionedOut<T> {
    /// Copies the first `min(struct_size, sizeof(T))` bytes of `v` to element `index` of the
    /// caller's array (elements `struct_size` bytes apart), with `struct_size` set to the bytes
    /// filled.
    ///
    /// # Safety
    /// The caller's array holds more than `index` elements.
    pub(crate) unsafe fn write_at(&self, index: usize, mut v: T) {
        let n = self.stride.min(std::mem::size_of::<T>());
        std::ptr::write_unaligned(&mut v as *mut T as *mut u32, n as u32);
        let dst = (self.ptr as *mut u8).add(index * self.stride);
        std::ptr::copy_nonoverlapping(&v as *const T as *const u8, dst, n);
    }

    /// [`VersionedOut::write_at`] the single element.
    pub(crate) fn write(&self, v: T) {
        // SAFETY: element 0 exists by the contract of `versioned_out`.
        unsafe { self.write_at(0, v) }
    }
}
