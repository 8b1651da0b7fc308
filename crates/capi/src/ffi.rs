//! Every read of the host's memory and every write into it, each with its contract. The
//! exported functions pass their callers' pointers here; nothing else in the crate touches a
//! raw pointer. A NULL pointer where a value is required is a typed error, never a read.
use crate::status::{Error, Result, TesseraStatus};
use std::ffi::{c_char, CStr};

fn null(what: &str) -> Error {
    Error::new(TesseraStatus::NullPointer, format!("{what} is NULL"))
}

/// `len * per` elements at `ptr`: empty when `len` is 0 (whatever `ptr`), an error when `ptr`
/// is NULL, misaligned, or the element count overflows.
///
/// # Safety
/// When `len > 0` and `ptr` is not NULL, `ptr` addresses `len * per` readable, initialized `T`
/// that nothing writes during the returned borrow.
pub(crate) unsafe fn read_slice<'a, T>(
    ptr: *const T,
    len: usize,
    per: usize,
    what: &str,
) -> Result<&'a [T]> {
    if len == 0 {
        return Ok(&[]);
    }
    if ptr.is_null() {
        return Err(null(what));
    }
    let n = len.checked_mul(per).ok_or_else(|| {
        Error::new(
            TesseraStatus::WrongSize,
            format!("{what}: {len} elements of {per} overflow the address space"),
        )
    })?;
    if !ptr.is_aligned() {
        return Err(Error::new(
            TesseraStatus::InvalidArgument,
            format!("{what} is not aligned for its element type"),
        ));
    }
    // SAFETY: non-null and aligned (checked); the caller vouches for the length and contents.
    Ok(unsafe { std::slice::from_raw_parts(ptr, n) })
}

/// `len` writable bytes at `ptr`.
///
/// # Safety
/// `ptr` is NULL or addresses `len` writable bytes nothing else accesses during the borrow.
pub(crate) unsafe fn write_slice<'a>(ptr: *mut u8, len: usize, what: &str) -> Result<&'a mut [u8]> {
    if ptr.is_null() {
        return Err(null(what));
    }
    // SAFETY: non-null; bytes need no alignment; the caller vouches for the length.
    Ok(unsafe { std::slice::from_raw_parts_mut(ptr, len) })
}

/// A NUL-terminated UTF-8 string, or None for NULL.
///
/// # Safety
/// `ptr` is NULL or points to a NUL-terminated string.
pub(crate) unsafe fn read_str(ptr: *const c_char, what: &str) -> Result<Option<String>> {
    if ptr.is_null() {
        return Ok(None);
    }
    // SAFETY: the caller's contract.
    let s = unsafe { CStr::from_ptr(ptr) };
    s.to_str().map(|s| Some(s.to_owned())).map_err(|_| {
        Error::new(
            TesseraStatus::InvalidArgument,
            format!("{what} is not UTF-8"),
        )
    })
}

/// A copy of `*ptr`, or None for NULL.
///
/// # Safety
/// `ptr` is NULL or points to a readable, initialized `T`.
pub(crate) unsafe fn read_opt<T: Copy>(ptr: *const T) -> Option<T> {
    if ptr.is_null() || !ptr.is_aligned() {
        return None;
    }
    // SAFETY: non-null and aligned; the caller's contract.
    Some(unsafe { ptr.read() })
}

/// A copy of `*ptr`; NULL is an error.
///
/// # Safety
/// As [`read_opt`].
pub(crate) unsafe fn read_required<T: Copy>(ptr: *const T, what: &str) -> Result<T> {
    // SAFETY: the caller's contract.
    unsafe { read_opt(ptr) }.ok_or_else(|| null(what))
}

/// Writes `value` to `*ptr`; NULL is an error.
///
/// # Safety
/// `ptr` is NULL or points to writable memory for a `T`.
pub(crate) unsafe fn out_write<T>(ptr: *mut T, value: T, what: &str) -> Result<()> {
    if ptr.is_null() {
        return Err(null(what));
    }
    if !ptr.is_aligned() {
        return Err(Error::new(
            TesseraStatus::InvalidArgument,
            format!("{what} is not aligned for its type"),
        ));
    }
    // SAFETY: non-null and aligned; the caller's contract.
    unsafe { ptr.write(value) };
    Ok(())
}

/// Writes `value` to `*ptr` unless `ptr` is NULL (an optional output).
///
/// # Safety
/// As [`out_write`].
pub(crate) unsafe fn out_write_opt<T>(ptr: *mut T, value: T) {
    // SAFETY: the caller's contract; NULL is skipped.
    let _ = unsafe { out_write_if_some(ptr, value) };
}

unsafe fn out_write_if_some<T>(ptr: *mut T, value: T) -> Result<()> {
    if ptr.is_null() {
        return Ok(());
    }
    // SAFETY: the caller's contract.
    unsafe { out_write(ptr, value, "output") }
}

/// Copies `s` into `buffer` NUL-terminated, truncated to `capacity - 1` bytes (at a character
/// boundary); nothing when `buffer` is NULL or `capacity` is 0.
///
/// # Safety
/// `buffer` is NULL or points to `capacity` writable bytes.
pub(crate) unsafe fn write_c_string(s: &str, buffer: *mut c_char, capacity: usize) {
    if buffer.is_null() || capacity == 0 {
        return;
    }
    let mut n = s.len().min(capacity - 1);
    while !s.is_char_boundary(n) {
        n -= 1;
    }
    // SAFETY: the caller's contract: `capacity` bytes, of which n + 1 are written.
    unsafe {
        std::ptr::copy_nonoverlapping(s.as_ptr(), buffer.cast::<u8>(), n);
        buffer.add(n).write(0);
    }
}

/// Copies `values` to `ptr`; NULL or a misaligned pointer is an error.
///
/// # Safety
/// `ptr` is NULL or addresses `values.len()` writable `f64` nothing else accesses during the
/// call.
pub(crate) unsafe fn write_f64s(ptr: *mut f64, values: &[f64], what: &str) -> Result<()> {
    if ptr.is_null() {
        return Err(null(what));
    }
    if !ptr.is_aligned() {
        return Err(Error::new(
            TesseraStatus::InvalidArgument,
            format!("{what} is not aligned for double"),
        ));
    }
    // SAFETY: non-null and aligned; the caller vouches for the length.
    unsafe { std::ptr::copy_nonoverlapping(values.as_ptr(), ptr, values.len()) };
    Ok(())
}
