//! Validation of deserialised shapes. Shapes that cache derived data (meshes, heightfields,
//! hulls, scaled shapes, compounds) load through a raw struct and `TryFrom`, which re-checks
//! the constructor's invariants. Some serde formats (postcard) drop the message of such an
//! error, so the check also records it here for the loader to report
//! ([`take_load_error`]).

use crate::error::{CaromError, Result};
use std::cell::RefCell;

thread_local! {
    static LAST: RefCell<Option<CaromError>> = const { RefCell::new(None) };
}

/// Passes `r` through, remembering its error (if any) for [`take_load_error`].
pub(crate) fn record<T>(r: Result<T>) -> Result<T> {
    if let Err(e) = &r {
        LAST.with(|l| *l.borrow_mut() = Some(e.clone()));
    }
    r
}

/// The last validation error raised while deserialising a shape on this thread, taken
/// (cleared). Loaders call it when a decode fails to report which check failed.
pub fn take_load_error() -> Option<CaromError> {
    LAST.with(|l| l.borrow_mut().take())
}

/// Clears any recorded error; loaders call it before decoding.
pub fn clear_load_error() {
    LAST.with(|l| *l.borrow_mut() = None);
}
