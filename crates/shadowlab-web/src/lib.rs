//! shadowlab's lab in the browser (docs/web.md): the page (web/index.html) opens the GPU with
//! [`open`], then asks for one view compared at a time with [`run`]; [`picture`] hands it each
//! technique's images. The work itself is [`compare::run`], plain Rust shared with native
//! builds (and tested there). In the browser the GPU's waits suspend under JSPI
//! (`shadowlab_gpu::web`), so `run` is a JSPI export: JavaScript receives a promise.

pub mod compare;

#[cfg(target_arch = "wasm32")]
#[allow(deprecated)] // wasm-bindgen marks its JSPI support experimental
mod browser {
    use std::cell::RefCell;

    use shadowlab_gpu::Gpu;
    use wasm_bindgen::prelude::*;

    use crate::compare::{self, Pictures, Request};

    thread_local! {
        /// The page's one device, opened by `open` (kept for the page's life).
        static GPU: RefCell<Option<&'static Gpu>> = const { RefCell::new(None) };
        /// The last run's pictures, for `picture`.
        static PICTURES: RefCell<Vec<Pictures>> = const { RefCell::new(Vec::new()) };
    }

    #[wasm_bindgen]
    extern "C" {
        #[wasm_bindgen(js_namespace = console, js_name = error)]
        fn console_error(message: &str);
    }

    /// A panic (a bug: every expected failure is an error value) ends the module's use: its
    /// message goes to the console and to `globalThis.shadowlabPanic`, which the page shows.
    fn report_panics() {
        std::panic::set_hook(Box::new(|info| {
            let message = format!("shadowlab panicked: {info}");
            console_error(&message);
            let _ = js_sys::Reflect::set(&js_sys::global(), &JsValue::from_str("shadowlabPanic"), &JsValue::from_str(&message));
        }));
    }

    /// Opens the browser's WebGPU adapter and device; resolves to the adapter's description.
    /// Once the device is lost (a GPU reset, a tab the browser froze), opens a new one.
    #[wasm_bindgen]
    pub async fn open() -> Result<String, JsValue> {
        report_panics();
        if let Some(gpu) = GPU.with(|g| *g.borrow()).filter(|g| g.lost().is_none()) {
            return Ok(gpu.adapter_summary());
        }
        let gpu: &'static Gpu = Box::leak(Box::new(Gpu::open().await.map_err(|e| JsValue::from_str(&e.to_string()))?));
        GPU.with(|g| *g.borrow_mut() = Some(gpu));
        Ok(gpu.adapter_summary())
    }

    /// Runs the request (JSON of `compare::Request`) and returns the outcome's JSON, or
    /// `{"error": MESSAGE}`; `"lost": true` beside it when the device was lost (the page then
    /// calls `open` again, which makes a new one, and repeats the run). Needs `open` first.
    #[wasm_bindgen(jspi)]
    pub fn run(request: String) -> String {
        let gpu = GPU.with(|g| *g.borrow());
        let result = (|| {
            let gpu = gpu.ok_or("the GPU is not open (call open first)")?;
            if let Some(why) = gpu.lost() {
                return Err(format!("the GPU device was lost ({why})"));
            }
            let req: Request = serde_json::from_str(&request).map_err(|e| format!("bad request: {e}"))?;
            let (outcome, pictures) = compare::run(gpu, &req)?;
            PICTURES.with(|p| *p.borrow_mut() = pictures);
            serde_json::to_string(&outcome).map_err(|e| e.to_string())
        })();
        let lost = gpu.is_some_and(|g| g.lost().is_some());
        result.unwrap_or_else(|e: String| serde_json::json!({ "error": e, "lost": lost }).to_string())
    }

    /// Destroys the device, as a GPU reset would (tests the page's recovery).
    #[wasm_bindgen]
    pub fn lose_device() {
        if let Some(gpu) = GPU.with(|g| *g.borrow()) {
            gpu.device.destroy();
        }
    }

    /// Technique `index`'s picture of the last run, RGBA8: `"shaded"` or `"error"` (empty if
    /// there is none).
    #[wasm_bindgen]
    pub fn picture(index: usize, which: &str) -> Vec<u8> {
        PICTURES.with(|p| {
            p.borrow().get(index).map_or_else(Vec::new, |pic| if which == "error" { pic.error.clone() } else { pic.shaded.clone() })
        })
    }

    /// The registry's techniques (name, lights, storage buffers a stage, and why the open
    /// device cannot run it, if so) and the built-in scenes (JSON), for the page's pickers.
    #[wasm_bindgen]
    pub fn catalogue() -> String {
        let limits = GPU.with(|g| g.borrow().map(|gpu| gpu.limits.clone()));
        let techniques: Vec<serde_json::Value> = shadowlab_gpu::registry::REGISTRY
            .iter()
            .map(|i| {
                let unavailable = limits.as_ref().and_then(|l| i.check_limits(l).err()).map(|e| e.to_string());
                serde_json::json!({ "name": i.name, "lights": i.lights, "unavailable": unavailable })
            })
            .collect();
        let scenes: Vec<serde_json::Value> = shadowlab_core::builtin::BUILTIN_SCENES
            .iter()
            .map(|s| serde_json::json!({ "name": s.name, "lights": (s.build)().lights.len() }))
            .collect();
        serde_json::json!({ "techniques": techniques, "scenes": scenes }).to_string()
    }
}
