//! Waiting in the browser (wasm32). A page cannot block its thread, and wgpu's callbacks (a
//! buffer mapped, submitted work done) only run when the event loop does. JSPI (JS Promise
//! Integration) suspends the wasm stack on a promise while the event loop runs, then resumes it:
//! [`block_until`] yields to the event loop until a callback has set its flag, so the waits of
//! [`crate::Gpu`] (and every readback above them) keep their native, synchronous shape. It
//! must run under a JSPI export (`#[wasm_bindgen(jspi)]`, the web crate's entry points); the
//! browser must offer JSPI (Chromium 137+, Firefox 153+; docs/web.md).

use std::sync::atomic::{AtomicBool, Ordering};

use wasm_bindgen::JsValue;

/// A promise resolved on the next turn of the event loop (a zero timeout).
fn next_turn() -> js_sys::Promise {
    js_sys::Promise::new(&mut |resolve, _reject| {
        let global = js_sys::global();
        let set_timeout = js_sys::Reflect::get(&global, &JsValue::from_str("setTimeout")).expect("setTimeout");
        let set_timeout: js_sys::Function = set_timeout.into();
        let _ = set_timeout.call2(&global, &resolve, &JsValue::from_f64(0.0));
    })
}

/// Yields to the event loop (suspending under JSPI) until `done` is set, or `give_up` says
/// it never will be (a lost device).
pub fn block_until(done: &AtomicBool, give_up: impl Fn() -> bool) {
    while !done.load(Ordering::Acquire) && !give_up() {
        #[allow(deprecated)] // js-sys marks its JSPI support experimental
        js_sys::futures::jspi_block_on_promise(&next_turn()).expect("a zero timeout resolves");
    }
}
