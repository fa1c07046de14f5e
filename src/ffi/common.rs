//! Status codes, last-error storage, the panic fence, version and threading.

use crate::Error;
use std::cell::RefCell;
use std::ffi::{c_char, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::{Arc, RwLock};

/// Version of the C ABI. Incremented on any incompatible change to a function signature or to
/// the layout of an existing struct field. Adding functions or appending struct fields (behind
/// `struct_size`) does not change it.
pub const PLEAT_ABI_VERSION: u32 = 1;

/// Result of every fallible pleat function. `PLEAT_STATUS_OK` (0) is success; on any other
/// value no output was written and `pleat_last_error()` says why.
#[repr(i32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PleatStatus {
    /// Success.
    Ok = 0,
    /// A parameter is NULL, out of range, NaN, or inconsistent with another.
    InvalidArgument = 1,
    /// The mesh violates a precondition (index out of range, non-finite coordinate, ...).
    InvalidMesh = 2,
    /// A file could not be opened, read or written.
    Io = 3,
    /// A file's content could not be parsed.
    Parse = 4,
    /// A numerical method failed.
    Numerical = 5,
    /// The progress callback asked to stop.
    Cancelled = 6,
    /// A size or memory limit would be exceeded (including a caller buffer that is too small).
    LimitExceeded = 7,
    /// An allocation failed.
    OutOfMemory = 8,
    /// A bug in pleat (including a caught panic). Please report it.
    Internal = 9,
    /// This build of pleat was compiled without the capability (cargo feature) needed.
    Unsupported = 10,
}

impl PleatStatus {
    pub(crate) fn of(e: &Error) -> PleatStatus {
        match e {
            Error::InvalidArgument(_) => PleatStatus::InvalidArgument,
            Error::InvalidMesh(_) => PleatStatus::InvalidMesh,
            Error::Io { .. } => PleatStatus::Io,
            Error::Parse { .. } => PleatStatus::Parse,
            Error::Numerical(_) => PleatStatus::Numerical,
            Error::Cancelled => PleatStatus::Cancelled,
            Error::LimitExceeded(_) => PleatStatus::LimitExceeded,
            Error::OutOfMemory => PleatStatus::OutOfMemory,
            Error::Internal(_) => PleatStatus::Internal,
            Error::Unsupported(_) => PleatStatus::Unsupported,
        }
    }
}

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

fn set_last_error(msg: &str) {
    let clean: String = msg.chars().filter(|&c| c != '\0').collect();
    let c = CString::new(clean).unwrap_or_default();
    LAST_ERROR.with(|e| *e.borrow_mut() = c);
}

/// Records `e` as this thread's last error and returns its status code.
pub(crate) fn fail(e: Error) -> PleatStatus {
    set_last_error(&e.to_string());
    PleatStatus::of(&e)
}

fn panic_message(p: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = p.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = p.downcast_ref::<String>() {
        s.clone()
    } else {
        "unknown panic payload".to_string()
    }
}

/// The panic fence: runs `f` on pleat's thread pool, catches panics, maps errors to statuses and
/// records the message. Every `extern "C"` function that can fail goes through here or through
/// [`guard_progress`] (the same fence with a progress relay); both end in `status_of`. The
/// arguments are checked inside `f` with the helpers of `ffi::boundary` (which imports this
/// module, never the reverse).
pub(crate) fn guard(f: impl FnOnce() -> crate::Result<()>) -> PleatStatus {
    status_of(catch_unwind(AssertUnwindSafe(|| with_pool(f))))
}

/// Maps the outcome of a fenced call to its status, recording the message of a failure (and
/// clearing it on success).
fn status_of(result: std::thread::Result<crate::Result<()>>) -> PleatStatus {
    match result {
        Ok(Ok(())) => {
            set_last_error("");
            PleatStatus::Ok
        }
        Ok(Err(e)) => fail(e),
        Err(p) => fail(Error::Internal(format!("panic: {}", panic_message(&*p)))),
    }
}

/// Records that this build was compiled without the cargo feature `feature` and returns
/// `PLEAT_STATUS_UNSUPPORTED` (for entry points whose capability was left out; the one
/// message of the `requires!` macro).
#[allow(dead_code)] // used only by builds that leave a capability out
pub(crate) fn unsupported(feature: &str) -> PleatStatus {
    set_last_error(&format!(
        "this build of pleat was compiled without the `{feature}` capability \
         (see pleat_has_feature)"
    ));
    PleatStatus::Unsupported
}

/// `Err(InvalidArgument)` naming a NULL pointer parameter.
pub(crate) fn null_arg(name: &str) -> Error {
    Error::InvalidArgument(format!("`{name}` is NULL"))
}

/// Reads a NUL-terminated UTF-8 string parameter.
///
/// # Safety
/// `p` is NULL or points to a NUL-terminated string.
pub(crate) unsafe fn c_str_arg<'a>(p: *const c_char, name: &str) -> crate::Result<&'a str> {
    if p.is_null() {
        return Err(null_arg(name));
    }
    CStr::from_ptr(p)
        .to_str()
        .map_err(|_| Error::InvalidArgument(format!("`{name}` is not valid UTF-8")))
}

// ---------------------------------------------------------------------------------------------
// Thread pool

static POOL: RwLock<Option<Arc<rayon::ThreadPool>>> = RwLock::new(None);

/// Moves a closure that captures caller pointers onto a pool thread. Sound because the calling
/// thread blocks in `install` until the closure has finished, so every pointer it captured stays
/// valid, and nothing it touches is thread-local (the last-error slot is written after return).
struct AssertSend<F>(F);
// SAFETY: see the type's doc comment.
unsafe impl<F> Send for AssertSend<F> {}

/// The pool set by `pleat_set_thread_count`, or `None` for rayon's global pool.
pub(crate) fn current_pool() -> Option<Arc<rayon::ThreadPool>> {
    POOL.read().ok().and_then(|g| g.clone())
}

fn with_pool<T: Send>(f: impl FnOnce() -> T) -> T {
    match current_pool() {
        Some(p) => {
            let job = AssertSend(f);
            p.install(move || {
                let job = job;
                (job.0)()
            })
        }
        None => f(),
    }
}

/// Sets the number of worker threads pleat uses for subsequent calls from any thread.
///
/// `n = 0` means one per core (rayon's global pool, the default). Results do not depend on the
/// thread count: the same input and parameters give the same output bytes.
/// Not safe to call while another thread is inside a pleat call that uses the pool (that call
/// keeps the old pool until it returns).
#[no_mangle]
pub extern "C" fn pleat_set_thread_count(n: u32) -> PleatStatus {
    guard(|| {
        let new = if n == 0 {
            None
        } else {
            let p = rayon::ThreadPoolBuilder::new()
                .num_threads(n as usize)
                .thread_name(|i| format!("pleat-{i}"))
                .build()
                .map_err(|e| Error::Internal(format!("cannot start {n} threads: {e}")))?;
            Some(Arc::new(p))
        };
        let mut g = POOL
            .write()
            .map_err(|_| Error::Internal("thread pool lock poisoned".into()))?;
        *g = new;
        Ok(())
    })
}

/// The boundary of exports that answer a value instead of a status (counts, flags): the value
/// of `f`, or `fallback` if it panics.
pub(crate) fn guard_value<T>(fallback: T, f: impl FnOnce() -> T) -> T {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or(fallback)
}

/// Number of worker threads the next pleat call will use (≥ 1).
#[no_mangle]
pub extern "C" fn pleat_thread_count() -> u32 {
    guard_value(1, || with_pool(rayon::current_num_threads) as u32)
}

// ---------------------------------------------------------------------------------------------
// Errors and version

/// The message of the last failed pleat call on this thread, as a NUL-terminated UTF-8 string
/// (empty after a successful call). Never NULL. The pointer stays valid until the next pleat
/// call on this thread; copy it if you need it longer.
#[no_mangle]
pub extern "C" fn pleat_last_error() -> *const c_char {
    LAST_ERROR.with(|e| e.borrow().as_ptr())
}

/// Copies the last error message of this thread into `buf` (capacity `len` bytes, always
/// NUL-terminated when `len > 0`, truncated if needed) and writes the full length without the
/// NUL to `needed` (may be NULL). `buf` may be NULL when `len` is 0, to query the size.
///
/// # Safety
/// `buf` points to `len` writable bytes (or is NULL with `len == 0`); `needed` is NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn pleat_last_error_message(
    buf: *mut c_char,
    len: usize,
    needed: *mut usize,
) -> PleatStatus {
    let msg: Vec<u8> = LAST_ERROR.with(|e| e.borrow().as_bytes().to_vec());
    if !needed.is_null() {
        *needed = msg.len();
    }
    if len == 0 {
        return PleatStatus::Ok;
    }
    if buf.is_null() {
        // Do not overwrite the message being asked for.
        return PleatStatus::InvalidArgument;
    }
    let n = msg.len().min(len - 1);
    std::ptr::copy_nonoverlapping(msg.as_ptr(), buf as *mut u8, n);
    *buf.add(n) = 0;
    PleatStatus::Ok
}

static VERSION: &CStr =
    match CStr::from_bytes_with_nul(concat!(env!("CARGO_PKG_VERSION"), "\0").as_bytes()) {
        Ok(v) => v,
        Err(_) => c"unknown",
    };

/// The library version (`major.minor.patch`, as in Cargo.toml), a static string; never NULL.
#[no_mangle]
pub extern "C" fn pleat_version() -> *const c_char {
    VERSION.as_ptr()
}

/// The C ABI version the library was built with; compare with the header's `PLEAT_ABI_VERSION`.
#[no_mangle]
pub extern "C" fn pleat_abi_version() -> u32 {
    PLEAT_ABI_VERSION
}

/// 1 when this build includes the capability `name` ("lod", "cage", "wrinkle", "io-gltf",
/// "bake", "tfw"), 0 otherwise or when `name` is NULL or unknown.
///
/// # Safety
/// `name` is NULL or a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn pleat_has_feature(name: *const c_char) -> u32 {
    let Ok(name) = c_str_arg(name, "name") else {
        return 0;
    };
    const BUILT: [(&str, bool); 6] = [
        ("lod", cfg!(feature = "lod")),
        ("cage", cfg!(feature = "cage")),
        ("wrinkle", cfg!(feature = "wrinkle")),
        ("io-gltf", cfg!(feature = "io-gltf")),
        ("bake", cfg!(feature = "bake")),
        ("tfw", cfg!(feature = "tfw")),
    ];
    let on = BUILT.iter().any(|&(n, built)| n == name && built);
    on as u32
}

/// Progress information passed to a [`PleatProgressFn`].
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct PleatProgress {
    /// Name of the running stage, NUL-terminated, valid during the callback only.
    pub stage: *const c_char,
    /// Fraction of the whole operation done, in [0, 1].
    pub fraction: f64,
}

/// Progress callback of long operations. Called on the calling thread only, with the caller's
/// `user_data`. Return 0 to continue, non-zero to cancel: the operation then returns
/// `PLEAT_STATUS_CANCELLED` promptly and writes no output.
pub type PleatProgressFn = Option<
    unsafe extern "C" fn(user_data: *mut std::ffi::c_void, info: *const PleatProgress) -> i32,
>;

// ---------------------------------------------------------------------------------------------
// Long operations with progress and cancellation

/// Calls the C progress callback; returns `true` to continue.
///
/// # Safety
/// `cb` and `user_data` are as the caller of the pleat entry point passed them.
unsafe fn call_progress(
    cb: PleatProgressFn,
    user_data: *mut std::ffi::c_void,
    stage: &str,
    fraction: f64,
) -> bool {
    let Some(f) = cb else { return true };
    let stage = CString::new(stage.replace('\0', "")).unwrap_or_default();
    let info = PleatProgress {
        stage: stage.as_ptr(),
        fraction: fraction.clamp(0.0, 1.0),
    };
    f(user_data, &info) == 0
}

enum Msg {
    Progress(String, f64),
    Done(std::thread::Result<crate::Result<()>>),
}

/// The panic fence for long operations that report progress.
///
/// `f` receives a Rust progress closure (return `false` = cancel). The C callback `cb` is always
/// invoked on the calling thread: without a custom pool `f` runs on the calling thread; with a
/// pool set by `pleat_set_thread_count`, `f` runs on a pool worker while the calling thread
/// relays each progress report to `cb` and sends its answer back; the worker waits for it.
pub(crate) fn guard_progress(
    cb: PleatProgressFn,
    user_data: *mut std::ffi::c_void,
    f: impl FnOnce(&mut dyn FnMut(crate::Progress<'_>) -> bool) -> crate::Result<()>,
) -> PleatStatus {
    let result = match current_pool() {
        None => catch_unwind(AssertUnwindSafe(|| {
            // SAFETY: cb/user_data come straight from the C caller, on its thread.
            let mut relay = |p: crate::Progress<'_>| unsafe {
                call_progress(cb, user_data, p.stage, p.fraction)
            };
            f(&mut relay)
        })),
        Some(pool) => run_on_pool(&pool, cb, user_data, f),
    };
    status_of(result)
}

/// [`guard_progress`] on a pool of its own with `threads` workers when `threads > 0` (a
/// per-call thread count; the callback still runs on the calling thread), else exactly
/// [`guard_progress`].
#[cfg_attr(not(feature = "bake"), allow(dead_code))]
pub(crate) fn guard_progress_threads(
    threads: u32,
    cb: PleatProgressFn,
    user_data: *mut std::ffi::c_void,
    f: impl FnOnce(&mut dyn FnMut(crate::Progress<'_>) -> bool) -> crate::Result<()>,
) -> PleatStatus {
    if threads == 0 {
        return guard_progress(cb, user_data, f);
    }
    let pool = match rayon::ThreadPoolBuilder::new()
        .num_threads(threads as usize)
        .thread_name(|i| format!("pleat-call-{i}"))
        .build()
    {
        Ok(p) => p,
        Err(e) => {
            return fail(Error::Internal(format!(
                "cannot start {threads} threads: {e}"
            )))
        }
    };
    status_of(run_on_pool(&pool, cb, user_data, f))
}

fn run_on_pool(
    pool: &rayon::ThreadPool,
    cb: PleatProgressFn,
    user_data: *mut std::ffi::c_void,
    f: impl FnOnce(&mut dyn FnMut(crate::Progress<'_>) -> bool) -> crate::Result<()>,
) -> std::thread::Result<crate::Result<()>> {
    // The worker waits for the callback's answer at every report, so a
    // cancellation takes effect at exactly the report that asked for it,
    // whatever the thread count (reports are coarse: the round trip is cheap).
    let (tx, rx) = std::sync::mpsc::channel::<Msg>();
    let (answer_tx, answer_rx) = std::sync::mpsc::channel::<bool>();
    let job = AssertSend(f);
    pool.in_place_scope(|s| {
        s.spawn(move |_| {
            let job = job;
            let progress_tx = tx.clone();
            let r = catch_unwind(AssertUnwindSafe(|| {
                let mut relay = |p: crate::Progress<'_>| {
                    if progress_tx
                        .send(Msg::Progress(p.stage.to_string(), p.fraction))
                        .is_err()
                    {
                        return false;
                    }
                    answer_rx.recv().unwrap_or(false)
                };
                (job.0)(&mut relay)
            }));
            let _ = tx.send(Msg::Done(r));
        });
        loop {
            match rx.recv() {
                Ok(Msg::Progress(stage, fraction)) => {
                    // SAFETY: on the calling thread, with the caller's callback.
                    let go_on = unsafe { call_progress(cb, user_data, &stage, fraction) };
                    let _ = answer_tx.send(go_on);
                }
                Ok(Msg::Done(r)) => return r,
                Err(_) => return Ok(Err(Error::Internal("worker vanished".into()))),
            }
        }
    })
}
