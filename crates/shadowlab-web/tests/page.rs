//! The page in headless Chromium (issue 40's automation contract, docs/web.md): `make test`
//! builds web/dist first (`make web`), and scripts/web-drive.py loads it from a loopback server.
//!
//! The page's numbers are compared with the native lab's on the same rasterizer: Chromium's
//! WebGPU runs on SwiftShader here, and Chromium ships SwiftShader's Vulkan driver, which the
//! native half opens (VK_ICD_FILENAMES, set in this test binary's own process before its only
//! device is made). Across rasterizers (llvmpipe against SwiftShader) the figures differ by
//! the pixels they rasterise differently (BENCHMARKS.md).

use std::path::{Path, PathBuf};
use std::process::Command;

use shadowlab_gpu::Gpu;
use shadowlab_web::compare::{self, Request};

const SWIFTSHADER_ICD: &str = "/usr/lib/chromium/vk_swiftshader_icd.json";
const TECHNIQUES: [&str; 3] = ["sm", "csm", "lt"];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

#[test]
fn the_page_gives_the_native_numbers_and_stays_usable_after_a_bad_spec() {
    if std::env::var_os("SHADOWLAB_SKIP_GPU_TESTS").is_some() {
        return;
    }
    let dist = root().join("web/dist");
    assert!(dist.join("index.html").exists(), "web/dist is missing: run `make web` (`make test` runs it first)");
    assert!(Path::new(SWIFTSHADER_ICD).exists(), "{SWIFTSHADER_ICD} missing: Debian's chromium package ships it (scripts/setup.sh)");
    // the only device of this process, on the page's rasterizer
    std::env::set_var("VK_ICD_FILENAMES", SWIFTSHADER_ICD);
    let gpu = Gpu::new().expect("SwiftShader's Vulkan device");
    assert!(gpu.info.name.contains("SwiftShader"), "native side on {}", gpu.adapter_summary());
    let req = Request {
        scene: "courtyard".into(),
        light: 0,
        width: 256,
        height: 256,
        techniques: TECHNIQUES.iter().map(|s| s.to_string()).collect(),
    };
    let (native, _) = compare::run(&gpu, &req).unwrap();

    let shot = std::env::temp_dir().join(format!("shadowlab-page-{}.png", std::process::id()));
    let first: String = TECHNIQUES.iter().map(|t| format!("&t={t}")).collect();
    let o = Command::new("python3")
        .arg(root().join("scripts/web-drive.py"))
        .args(["--dist", dist.to_str().unwrap(), "--screenshot", shot.to_str().unwrap()])
        .arg(format!("scene=courtyard{first}&size=256x256&run=1"))
        .arg("scene=courtyard&t=nosuch&size=256x256")
        .arg("scene=courtyard&t=sm&size=64x64")
        .arg("eval:window.shadowlab.loseDevice()")
        .arg("scene=courtyard&t=sm&size=64x64")
        .output()
        .expect("python3 scripts/web-drive.py");
    assert!(o.status.success(), "web-drive failed: {}", String::from_utf8_lossy(&o.stderr));
    let runs: serde_json::Value = serde_json::from_slice(&o.stdout).expect("web-drive's JSON");
    eprintln!("{}", serde_json::to_string_pretty(&runs).unwrap());

    let page = &runs[0];
    assert_eq!(page["title"], "shadowlab: done", "{page}");
    let result = &page["result"];
    for key in ["adapter", "width", "height", "timer", "techniques"] {
        assert!(!result[key].is_null(), "the result has `{key}`: {result}");
    }
    assert_eq!((result["width"].as_u64(), result["height"].as_u64()), (Some(256), Some(256)));
    let web = result["techniques"].as_array().unwrap();
    assert_eq!(web.len(), TECHNIQUES.len());
    for (w, n) in web.iter().zip(&native.techniques) {
        assert_eq!(w["label"], n.label.as_str());
        for key in ["false_lit_pct", "false_shadow_pct", "mae", "total_ms", "shadow_bytes"] {
            assert!(w[key].is_number(), "{key} of {w}");
        }
        let d = (w["wrong_pct"].as_f64().unwrap() - n.wrong_pct).abs();
        assert!(d <= 0.02, "{}: wrong % on the page {} against native {} (same rasterizer)", n.label, w["wrong_pct"], n.wrong_pct);
    }

    let bad = &runs[1];
    let title = bad["title"].as_str().unwrap();
    assert!(title.starts_with("shadowlab: error: ") && title.contains("nosuch"), "a bad spec is named: {title}");
    let again = &runs[2];
    assert_eq!(again["title"], "shadowlab: done", "the page still runs after an error: {again}");
    assert_eq!(again["result"]["techniques"][0]["label"], "sm");

    // a lost device: the page opens a new one and repeats the run, with the same figures
    let recovered = &runs[4];
    assert_eq!(recovered["title"], "shadowlab: done", "after a lost device: {recovered}");
    assert_eq!(recovered["result"]["recovered"], true, "{recovered}");
    assert_eq!(recovered["result"]["techniques"][0]["wrong_pct"], again["result"]["techniques"][0]["wrong_pct"]);

    assert_eq!(runs[5]["blank"], false, "the screenshot ({}) shows the page's pictures", shot.display());
    let _ = std::fs::remove_file(&shot);
}
