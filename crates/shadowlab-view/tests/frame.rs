//! The viewer's frame function without a window: on a still view its error image and metrics
//! are the lab's, pixel for pixel, for moved cameras and lights, animation times and a split.

use shadowlab_core::builtin::builtin;
use shadowlab_core::light::Light;
use shadowlab_core::metrics::{compare, error_image};
use shadowlab_gpu::lab::Lab;
use shadowlab_gpu::registry::Resolved;
use shadowlab_gpu::Gpu;
use shadowlab_view::fly::{orbit, sun_direction};
use shadowlab_view::render::{Evaluation, Look, Pose, RefStatus, Renderer, Right, Show};
use shadowlab_view::widgets::resolve_text;

fn gpu() -> Option<Gpu> {
    if std::env::var("SHADOWLAB_SKIP_GPU_TESTS").as_deref() == Ok("1") {
        eprintln!("SHADOWLAB_SKIP_GPU_TESTS=1: GPU test not run");
        return None;
    }
    Some(Gpu::new().unwrap_or_else(|e| panic!("{e} (set SHADOWLAB_SKIP_GPU_TESTS=1 to skip GPU tests)")))
}

/// Frames of a still pose until the reference is current and evaluated.
fn settle(r: &mut Renderer, pose: &Pose, look: &Look) -> Evaluation {
    let mut bands = 0;
    for _ in 0..200 {
        let info = r.frame(pose, look, true).unwrap();
        match info.reference {
            RefStatus::Current => return r.evaluation().expect("evaluated once current").clone(),
            RefStatus::Refining { done, of } => {
                assert!(done > bands && done < of, "one more band per frame: {done}/{of}");
                bands = done;
            }
            RefStatus::Stale => panic!("a still frame refines the reference"),
        }
    }
    panic!("the reference never became current");
}

/// What `compare` computes for the same view: the lab's reference, the technique, the image.
fn lab_error(lab: &Lab, pose: &Pose, spec: &Resolved, w: u32, h: u32) -> (Vec<u8>, shadowlab_core::metrics::ErrorMetrics) {
    lab.set_time(pose.time, pose.time).unwrap();
    let view = lab.view(&pose.camera, &pose.camera, &pose.light, w, h).unwrap();
    let rt = lab.reference(&view, 1).unwrap();
    let run = lab.run_resolved(&view, spec, 1).unwrap();
    (error_image(&rt.shaded, &run.visibility, &rt.visibility, &view.mask, true), compare(&run.visibility, &rt.visibility, &view.mask))
}

#[test]
fn the_error_view_is_the_labs_error_image() {
    let Some(gpu) = gpu() else { return };
    // courtyard: moving banners (time 7.5), a moved camera and sun; 96x80 takes several bands
    let scene = builtin("courtyard").unwrap();
    let (w, h) = (96, 80);
    let a = resolve_text("sm:res=128,pcf=3").unwrap();
    let b = resolve_text("csm:res=512").unwrap();
    let Light::Directional { direction } = scene.lights[0] else { panic!("courtyard has a sun") };
    // the sun turned by 12 degrees and raised by 5
    let (az, el) = shadowlab_view::fly::sun_angles(direction);
    let light = Light::Directional { direction: sun_direction(az + 12.0, el + 5.0) };
    let camera = orbit(&scene.camera, 6.0);
    let pose = Pose { camera, prev_camera: camera, light, time: 7.5, prev_time: 7.5 };
    let mut r = Renderer::new(Lab::new(&gpu, &scene).unwrap(), w, h, &scene.lights[0], a.clone(), Some(b.clone())).unwrap();
    assert!(shadowlab_view::render::REFERENCE_BAND_PIXELS < w * h || w * h <= 131_072);
    let look = Look { show: Show::Error, right: Right::Technique, divider: 0.5 };
    // a moving frame first: the light change re-creates the techniques, nothing is evaluated
    let moving = r.frame(&Pose { prev_camera: scene.camera, ..pose }, &look, false).unwrap();
    assert!(moving.recreated && moving.reference == RefStatus::Stale);
    let e = settle(&mut r, &pose, &look);
    let lab = Lab::new(&gpu, &scene).unwrap();
    for (side, spec) in [(&e.a, &a), (e.b.as_ref().expect("B evaluated"), &b)] {
        let (image, metrics) = lab_error(&lab, &pose, spec, w, h);
        assert_eq!(side.label, spec.label);
        let differ = side.error.chunks(4).zip(image.chunks(4)).filter(|(x, y)| x != y).count();
        assert_eq!(differ, 0, "{}: {differ} pixels differ from the lab's error image", spec.label);
        assert_eq!(side.metrics, metrics, "{}", spec.label);
        assert!(metrics.evaluated_pixels > 1000, "the view sees lit ground: {metrics:?}");
    }
    assert!(e.a.metrics.wrong_pct > 0.0, "a 128 map is coarse: the comparison has something to find: {:?}", e.a.metrics);
    // the next frame's picture shows A's error image left of the divider
    assert_eq!(r.frame(&pose, &look, true).unwrap().reference, RefStatus::Current);
    let pic = r.read_picture();
    let row = (h / 2) as usize;
    for x in [0usize, (w / 2 - 3) as usize] {
        let i = 4 * (row * w as usize + x);
        assert_eq!(&pic[i..i + 3], &e.a.error[i..i + 3], "picture at ({x},{row}) is A's error view");
    }
    for x in [(w / 2 + 3) as usize, (w - 1) as usize] {
        let i = 4 * (row * w as usize + x);
        assert_eq!(&pic[i..i + 3], &e.b.as_ref().unwrap().error[i..i + 3], "picture at ({x},{row}) is B's error view");
    }
    // an edit while still re-evaluates at once (the reference is kept)
    r.set_technique(false, Some(resolve_text("sm:res=64").unwrap()), &light).unwrap();
    let info = r.frame(&pose, &look, true).unwrap();
    assert_eq!(info.reference, RefStatus::Current);
    let e2 = r.evaluation().unwrap();
    assert_eq!(e2.a.label, "sm:res=64");
    assert!(e2.id > e.id);
    // moving again makes it stale, never traced per frame while moving
    let moved = Pose { camera: orbit(&camera, 5.0), prev_camera: camera, ..pose };
    assert_eq!(r.frame(&moved, &look, false).unwrap().reference, RefStatus::Stale);
}
