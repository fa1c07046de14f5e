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
        // SAFETY: repr(C), leading `struct_size: u32`, integer, real and raw-pointer fields only
        // (any bit pattern is a valid value).
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

// ---------------------------------------------------------------------------------------------
// Tests (run under Miri by `.ci/miri.sh`: no FFI calls, no threads, no file system)

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ffi::common::c_str_arg;

    /// A versioned struct as the C side sees it: version 1 is 16 bytes (`struct_size`, `a`,
    /// `b`), version 2 appends `c`.
    #[repr(C)]
    #[derive(Debug, Clone, Copy, PartialEq)]
    struct Params {
        struct_size: u32,
        a: u32,
        b: f64,
        c: f64,
    }

    fn params_default() -> Params {
        Params {
            struct_size: full_size::<Params>(),
            a: 7,
            b: 0.5,
            c: -1.0,
        }
    }

    versioned!(Params, 16, params_default);

    /// The first published version of `Params` (what an older caller compiled against).
    #[repr(C)]
    #[derive(Clone, Copy)]
    struct ParamsV1 {
        struct_size: u32,
        a: u32,
        b: f64,
    }

    fn message(e: Error) -> String {
        e.to_string()
    }

    #[test]
    fn arg_ref_borrows_or_names_the_null_parameter() {
        let x = 5u64;
        assert_eq!(unsafe { arg_ref(&x, "x") }.copied().unwrap(), 5);
        let e = unsafe { arg_ref::<u64>(std::ptr::null(), "mesh") }.unwrap_err();
        assert!(message(e).contains("`mesh` is NULL"));
        assert!(non_null(&x as *const u64, "x").is_ok());
        assert!(non_null(std::ptr::null::<u8>(), "out").is_err());
    }

    #[test]
    fn arg_slice_reads_exactly_the_given_values() {
        let v = [1.0f64, 2.0, 3.0];
        let s = unsafe { arg_slice(v.as_ptr(), 3, "positions") }.unwrap();
        assert_eq!(s, &v[..]);
        let empty = unsafe { arg_slice(v.as_ptr(), 0, "positions") }.unwrap();
        assert!(empty.is_empty());
        // a sub-range through an offset pointer stays inside the allocation
        let tail = unsafe { arg_slice(v.as_ptr().add(1), 2, "positions") }.unwrap();
        assert_eq!(tail, &[2.0, 3.0]);
        let e = unsafe { arg_slice::<f64>(std::ptr::null(), 0, "indices") }.unwrap_err();
        assert!(message(e).contains("`indices` is NULL"));
    }

    #[test]
    fn arg_slice_refuses_counts_beyond_the_address_space_without_reading() {
        let v = [0u32; 2];
        for len in [usize::MAX, usize::MAX / 4 + 1, isize::MAX as usize / 2] {
            let e = unsafe { arg_slice(v.as_ptr(), len, "indices") }.unwrap_err();
            assert!(message(e).contains("cannot hold"), "{len}");
        }
    }

    #[test]
    fn out_writes_once_and_arrays_by_offset() {
        let mut slot = 0u32;
        unsafe { arg_out(&mut slot, "out") }.unwrap().put(42);
        assert_eq!(slot, 42);
        let e = unsafe { arg_out::<u32>(std::ptr::null_mut(), "out_count") }.err();
        assert!(message(e.unwrap()).contains("`out_count` is NULL"));
        let mut arr = [0u16; 4];
        let out = unsafe { arg_out(arr.as_mut_ptr(), "out_values") }.unwrap();
        for i in 0..4 {
            unsafe { out.add(i) }.put(10 + i as u16);
        }
        assert_eq!(arr, [10, 11, 12, 13]);
    }

    #[test]
    fn boxed_handles_round_trip_through_destroy() {
        let mut h: *mut Vec<u8> = std::ptr::null_mut();
        unsafe { arg_out(&mut h, "out_handle") }
            .unwrap()
            .put_boxed(vec![1, 2, 3]);
        assert_eq!(unsafe { &*h }, &vec![1, 2, 3]);
        unsafe { destroy(h) };
        unsafe { destroy::<Vec<u8>>(std::ptr::null_mut()) };
    }

    #[test]
    fn destroy_contains_a_panicking_destructor() {
        struct Bomb;
        impl Drop for Bomb {
            fn drop(&mut self) {
                panic!("drop");
            }
        }
        let mut h: *mut Bomb = std::ptr::null_mut();
        unsafe { arg_out(&mut h, "h") }.unwrap().put_boxed(Bomb);
        let hook = std::panic::take_hook();
        std::panic::set_hook(Box::new(|_| {}));
        unsafe { destroy(h) };
        std::panic::set_hook(hook);
    }

    #[test]
    fn c_str_arg_reads_to_the_nul_and_checks_utf8() {
        let s = b"mesh.obj\0";
        let r = unsafe { c_str_arg(s.as_ptr().cast(), "path") }.unwrap();
        assert_eq!(r, "mesh.obj");
        let empty = b"\0";
        assert_eq!(
            unsafe { c_str_arg(empty.as_ptr().cast(), "path") }.unwrap(),
            ""
        );
        let bad = b"\xff\xfe\0";
        let e = unsafe { c_str_arg(bad.as_ptr().cast(), "path") }.unwrap_err();
        assert!(message(e).contains("not valid UTF-8"));
        let e = unsafe { c_str_arg(std::ptr::null(), "path") }.unwrap_err();
        assert!(message(e).contains("`path` is NULL"));
    }

    #[test]
    fn numbers_are_checked_with_the_parameter_named() {
        assert!(finite_slice(&[0.0, 1.0], "p").is_ok());
        let e = finite_slice(&[0.0, f64::NAN], "positions").unwrap_err();
        assert!(message(e).contains("positions[1] is NaN"));
        assert!(check_f64(1.0, true, "d", "> 0").is_ok());
        assert!(message(check_f64(-1.0, false, "d", "> 0").unwrap_err()).contains("d is -1"));
        assert!(check_range(3, 1, 3, "n").is_ok());
        assert!(message(check_range(4, 1, 3, "n").unwrap_err()).contains("allowed 1 to 3"));
        assert!(check_flags(0b101, 0b111, "flags").is_ok());
        assert!(message(check_flags(0b1000, 0b111, "flags").unwrap_err()).contains("0x8"));
        assert!(bool_field(1, "x").unwrap());
        assert!(!bool_field(0, "x").unwrap());
        assert!(bool_field(2, "x").is_err());
    }

    #[test]
    fn read_versioned_takes_null_as_defaults() {
        let p = unsafe { read_versioned::<Params>(std::ptr::null(), "params") }.unwrap();
        assert_eq!(p, params_default());
    }

    #[test]
    fn read_versioned_reads_only_an_older_callers_bytes() {
        // an older caller's struct is 16 bytes: reading must not touch bytes beyond it
        let old = ParamsV1 {
            struct_size: std::mem::size_of::<ParamsV1>() as u32,
            a: 3,
            b: 2.5,
        };
        let p = unsafe { read_versioned(&old as *const ParamsV1 as *const Params, "params") };
        let p = p.unwrap();
        assert_eq!((p.a, p.b, p.c), (3, 2.5, -1.0));
        assert_eq!(p.struct_size, full_size::<Params>());
        // a newer caller's larger struct: only our size is read
        #[repr(C)]
        struct ParamsV3 {
            v2: Params,
            d: u64,
        }
        let mut newer = ParamsV3 {
            v2: Params {
                a: 9,
                b: 1.0,
                c: 2.0,
                ..params_default()
            },
            d: 1,
        };
        newer.v2.struct_size = std::mem::size_of::<ParamsV3>() as u32;
        let p = unsafe { read_versioned(&newer as *const ParamsV3 as *const Params, "params") };
        let p = p.unwrap();
        assert_eq!((p.a, p.b, p.c), (9, 1.0, 2.0));
        assert_eq!(newer.d, 1);
    }

    #[test]
    fn read_versioned_refuses_a_short_struct_size() {
        let mut short = params_default();
        short.struct_size = 8;
        let e = unsafe { read_versioned(&short, "params") }.unwrap_err();
        let m = message(e);
        assert!(m.contains("params->struct_size is 8"), "{m}");
        assert!(m.contains("params_default()"), "{m}");
    }

    #[test]
    fn versioned_out_fills_only_the_callers_bytes() {
        // an older caller's output array of two 16-byte elements, followed by a guard value
        #[repr(C)]
        struct OldOut {
            items: [ParamsV1; 2],
            guard: u64,
        }
        let zero = ParamsV1 {
            struct_size: 16,
            a: 0,
            b: 0.0,
        };
        let mut out = OldOut {
            items: [zero; 2],
            guard: 0xdead_beef,
        };
        let p = &mut out as *mut OldOut as *mut Params;
        let vo = unsafe { versioned_out(p, "out_stats") }.unwrap().unwrap();
        for i in 0..2 {
            let v = Params {
                a: i as u32 + 1,
                b: 4.0,
                ..params_default()
            };
            unsafe { vo.write_at(i, v) };
        }
        assert_eq!((out.items[0].a, out.items[1].a), (1, 2));
        assert_eq!(out.items[1].b, 4.0);
        assert_eq!(out.items[0].struct_size, 16);
        assert_eq!(out.guard, 0xdead_beef);
        // a current caller gets the whole struct
        let mut full = params_default();
        full.c = 0.0;
        let vo = unsafe { required_versioned_out(&mut full, "out") }.unwrap();
        vo.write(params_default());
        assert_eq!(full, params_default());
        // NULL: optional, or named when required
        assert!(
            unsafe { versioned_out::<Params>(std::ptr::null_mut(), "o") }
                .unwrap()
                .is_none()
        );
        let e = unsafe { required_versioned_out::<Params>(std::ptr::null_mut(), "out_report") };
        assert!(message(e.err().unwrap()).contains("`out_report` is NULL"));
    }
}
