//! A small, complete [`Metrics`] for the readers' tests, and the record's own round trip.

use super::*;
use glam::Vec3;
use shadowlab_core::params::Value;

/// A small, complete record for the readers' tests.
pub fn metrics(frames: usize) -> Metrics {
    let camera = Camera { position: Vec3::new(0.0, 1.0, 3.0), target: Vec3::ZERO, fov_y_deg: 60.0, near: 0.1, far: 100.0 };
    let rec = |f: usize, w: f64| FrameRecord {
        frame: f,
        quality: ErrorMetrics { wrong_pct: w, false_lit_pct: w / 2.0, false_shadow_pct: w / 2.0, mae: 0.01, evaluated_pixels: 10 },
        flip_mean: w / 20.0,
        rays_traced: None,
        edge_pixels: 2,
        flicker_pct: (f > 0).then_some(w / 2.0),
        total_ms: 3.0,
        stages_ms: StagesMs::from([("sm.render".to_string(), 2.0)]),
    };
    let technique = |label: &str| Technique {
        label: label.into(),
        technique: "sm".into(),
        params: ParamValues(BTreeMap::from([("res".to_string(), Value::Integer(512)), ("fit".to_string(), Value::Choice("box".into()))])),
        quality: ErrorMetrics { wrong_pct: 1.25, false_lit_pct: 0.5, false_shadow_pct: 0.75, mae: 0.01, evaluated_pixels: 10 },
        flip_mean: 0.0625,
        flicker_pct: (frames > 1).then_some(0.5),
        shadow_data_bytes: 1048576,
        stages_ms: StagesMs::from([("sm.render".to_string(), 2.0)]),
        total_ms: 3.0,
        submits_per_frame: 1,
        stalls: vec![],
        setup_ms: 1.0,
        counters: BTreeMap::from([("fetches_per_pixel".to_string(), 9.0)]),
        sampling: None,
        degraded: vec![],
        images: Images { shaded: "a.png".into(), error: "b.png".into(), error_split: "c.png".into(), flip: "d.png".into(), extra: vec![] },
        visibility_npy: None,
        frames: (0..frames).map(|f| rec(f, 1.0 + f as f64)).collect(),
    };
    Metrics {
        schema_version: SCHEMA_VERSION,
        scene: "planebox".into(),
        scene_source: "builtin:planebox".into(),
        scene_transform: glam::Mat4::IDENTITY.to_cols_array_2d(),
        triangles: 14,
        has_cutouts: false,
        load_report: LoadReport::default(),
        camera,
        lights: vec![Light::Directional { direction: Vec3::new(0.0, -1.0, 0.0) }],
        light_index: 0,
        width: 4,
        height: 4,
        adapter: "x".into(),
        timer: "t".into(),
        stages_timer: "s".into(),
        repeat: 1,
        animation: Animation { dynamic_triangles: 0, dynamic_first: 14, time_unit: "frames".into(), start_time: 0.0, animations: vec![] },
        bvh: Bvh { gpu_bytes: 200, nodes: 3, bytes: 100, bytes_per_triangle: 7.1, depth: 2, build_ms: 0.1 },
        gbuffer_ms: 1.0,
        gbuffer_stages_ms: StagesMs::from([("gbuffer".to_string(), 1.0)]),
        frames,
        cameras: vec![camera; frames],
        reference: Reference {
            label: "rt".into(),
            evaluated_pixels: 10,
            edge_pixels: 2,
            stages_ms: StagesMs::new(),
            total_ms: 1.0,
            counters: BTreeMap::from([("rays_traced".to_string(), 10.0)]),
            frames: (0..frames)
                .map(|f| ReferenceFrame {
                    frame: f,
                    time: f as f32,
                    evaluated_pixels: 10,
                    edge_pixels: 2,
                    rays_traced: Some(10.0),
                    total_ms: 1.0,
                })
                .collect(),
        },
        techniques: vec![technique("sm:pcf=3"), technique("vsm:blur=5")],
        peak_rss_mib: Some(12.5),
        warnings: vec![],
    }
}

#[test]
fn round_trips_through_json() {
    for frames in [1, 3] {
        let m = metrics(frames);
        let back: Metrics = serde_json::from_str(&m.to_json().unwrap()).unwrap();
        assert_eq!(back, m);
    }
}

#[test]
fn unknown_and_missing_fields_are_errors() {
    let mut v = serde_json::to_value(metrics(1)).unwrap();
    v["techniques"][0]["wrong_percent"] = 1.0.into();
    assert!(serde_json::from_value::<Metrics>(v.clone()).is_err());
    v["techniques"][0].as_object_mut().unwrap().remove("wrong_percent");
    v["techniques"][0].as_object_mut().unwrap().remove("mae");
    assert!(serde_json::from_value::<Metrics>(v).is_err());
}
