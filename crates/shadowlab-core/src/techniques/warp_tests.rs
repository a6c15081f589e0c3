use super::*;

pub(super) fn lcg(seed: &mut u64) -> f32 {
    *seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    ((*seed >> 40) as f32) / (1u64 << 24) as f32
}

/// One sample at every texel centre: the uniform distribution.
fn uniform_points(res: usize) -> Vec<[f32; 2]> {
    (0..res * res).map(|i| [((i % res) as f32 + 0.5) / res as f32, ((i / res) as f32 + 0.5) / res as f32]).collect()
}

fn check_monotonic_onto(o: &[f32]) {
    let mut prev = 0.0f32;
    for s in 0..=1000 {
        let x = s as f32 / 1000.0;
        let v = if s == 1000 { 1.0 } else { x + eval_offset(o, x) };
        assert!(v >= prev - 1e-6, "not monotonic at {x}: {v} < {prev}");
        assert!((-1e-6..=1.0 + 1e-6).contains(&v), "{x} -> {v} leaves [0,1]");
        prev = v;
    }
    assert!(eval_offset(o, 0.0).abs() < 1e-6);
    assert!(o.last().unwrap().abs() < 1e-5, "o(1) = {}", o.last().unwrap());
}

#[test]
fn prefix_sum_by_hand() {
    let p = row_prefix(&[1.0, 2.0, 3.0, 0.0, 5.0, 5.0], 2, 3);
    assert_eq!(p, vec![1.0, 3.0, 6.0, 0.0, 5.0, 10.0]);
}

#[test]
fn uniform_samples_give_the_identity_warp() {
    let res = 32;
    let n = notw(&uniform_points(res), res, 16, true, 0, 0.0);
    assert!(n.warp.ox.iter().chain(&n.warp.oy).all(|o| o.abs() < 1e-6));
    let w = rtw(&vec![1.0; res * res], res, 4);
    for s in 0..=100 {
        let x = s as f32 / 100.0 * 0.999;
        let (a, b) = n.warp.apply(x, 1.0 - x);
        assert!((a - x).abs() < 1e-6 && (b - (1.0 - x)).abs() < 1e-6);
        let (a, b) = w.apply(x, x);
        assert!((a - x).abs() < 1e-5 && (b - x).abs() < 1e-5);
    }
}

#[test]
fn a_row_with_all_samples_in_one_half_maps_that_half_to_the_whole_row() {
    let res = 16;
    // uniform samples in the left half of row 5 only; no smoothing
    let mut c = vec![0.0f32; res * res];
    for k in 0..res / 2 {
        c[5 * res + k] = 3.0;
    }
    let o = row_warps(&c, res, 0, false);
    let row = &o[5 * res..6 * res];
    for s in 0..=50 {
        let x = 0.5 * s as f32 / 50.0;
        let expect = 2.0 * x; // [0, 0.5] stretched onto [0, 1]
        assert!((x + eval_offset(row, x) - expect).abs() < 1e-6, "x {x}");
    }
    // the empty right half collapses onto x' = 1
    assert!((0.6 + eval_offset(row, 0.6) - 1.0).abs() < 1e-6);
    // other rows are empty: identity
    assert!(o[..5 * res].iter().chain(&o[6 * res..]).all(|v| *v == 0.0));
    // the right half: mirrored
    let mut c = vec![0.0f32; res];
    for v in &mut c[res / 2..] {
        *v = 1.0;
    }
    let row = offsets_from_prefix(&row_prefix(&c, 1, res));
    assert!((0.75 + eval_offset(&row, 0.75) - 0.5).abs() < 1e-6);
}

#[test]
fn hand_computed_row_offsets() {
    // counts 1, 3 in a 2-texel row: g(1/2) = 1/4, g(1) = 1 -> o(1/2) = -1/4, o(1) = 0
    let o = offsets_from_prefix(&row_prefix(&[1.0, 3.0], 1, 2));
    assert_eq!(o, vec![-0.25, 0.0]);
    assert!((eval_offset(&o, 0.25) - (-0.125)).abs() < 1e-7); // x' = 1/8
    assert!((eval_offset(&o, 0.75) - (-0.125)).abs() < 1e-7); // x' = 5/8
}

#[test]
fn random_warps_are_monotonic_and_onto() {
    let mut seed = 7u64;
    let res = 64;
    // clustered points: a dense blob and a sparse background
    let pts: Vec<[f32; 2]> = (0..20000)
        .map(|i| {
            let (a, b) = (lcg(&mut seed), lcg(&mut seed));
            if i % 4 == 0 {
                [a, b]
            } else {
                [0.2 + 0.1 * a * a, 0.6 + 0.3 * b * b * b]
            }
        })
        .collect();
    for (window, interp, blur) in [(0, false, 0), (4, true, 0), (16, true, 0), (16, false, 0), (16, true, 4)] {
        let mix = if blur > 0 { 0.5 } else { 0.0 };
        let n = notw(&pts, res, window, interp, blur, mix);
        for i in 0..res {
            check_monotonic_onto(n.warp.row(i));
            check_monotonic_onto(&n.warp.column(i));
        }
        // every point stays in the map
        for p in &pts {
            let (x, y) = n.warp.apply(p[0], p[1]);
            assert!((0.0..=1.0).contains(&x) && (0.0..=1.0).contains(&y));
        }
    }
    let imp: Vec<f32> = (0..res * res).map(|_| lcg(&mut seed).powi(4)).collect();
    let w = rtw(&imp, res, 3);
    check_monotonic_onto(w.row(0));
    check_monotonic_onto(&w.column(0));
}

#[test]
fn smoothing_is_a_weighted_average_over_the_window() {
    // three rows of two edges: totals 1, 0, 3; window 2 (rows i-1..i+1)
    let offs = [0.4, 0.0, 9.0, 0.0, -0.2, 0.0];
    let s = smooth(&offs, &[1.0, 0.0, 3.0], 2, 2, false);
    assert!((s[0] - 0.4).abs() < 1e-6); // rows 0,1: only row 0 weighs
    assert!((s[2] - (0.4 - 0.6) / 4.0).abs() < 1e-6); // rows 0..2: (1*0.4 + 3*-0.2) / 4
    assert!((s[4] - (-0.2)).abs() < 1e-6);
    assert_eq!(smooth(&offs, &[1.0, 0.0, 3.0], 2, 0, false)[2], 0.0, "window 0 keeps row 1 (0 samples): 0 weight -> 0");
}

#[test]
fn the_tent_window_weighs_functions_by_distance_and_steps_less_between_neighbours() {
    // three rows as above, window 2 (half 1): weight 2 at distance 0, 1 at distance 1
    let offs = [0.4, 0.0, 9.0, 0.0, -0.2, 0.0];
    let s = smooth(&offs, &[1.0, 0.0, 3.0], 2, 2, true);
    assert!((s[0] - 0.4).abs() < 1e-6, "rows 0, 1: only row 0 weighs");
    assert!((s[2] - (0.4 - 0.6) / 4.0).abs() < 1e-6, "row 1: rows 0 and 2 both at distance 1");
    // sparse functions (every third row has samples, 1-5 of them) with scattered offsets,
    // window 16: the box's neighbours differ by a step wherever a function enters or leaves;
    // the tent's steps are about half as large (0.143 vs 0.072 here)
    let rows = 64;
    let offs: Vec<f32> = (0..rows).map(|r| ((r * 5) % 7) as f32 / 7.0).collect();
    let totals: Vec<f32> = (0..rows).map(|r| if r % 3 == 0 { (1 + (r * 3) % 5) as f32 } else { 0.0 }).collect();
    let steps = |v: &[f32]| v[8..rows - 8].windows(2).map(|w| (w[1] - w[0]).abs()).fold(0.0f32, f32::max);
    let (boxed, tent) = (smooth(&offs, &totals, 1, 16, false), smooth(&offs, &totals, 1, 16, true));
    assert!((steps(&boxed) - 1.0 / 7.0).abs() < 1e-5, "box steps: {boxed:?}");
    assert!(steps(&tent) < 0.55 * steps(&boxed), "tent steps {} vs box {}", steps(&tent), steps(&boxed));
}

#[test]
fn warping_evens_out_the_counts() {
    // perspective-like density: many samples near y = 0, few far away
    let mut seed = 3u64;
    let res = 64;
    let pts: Vec<[f32; 2]> = (0..200_000).map(|_| [0.3 + 0.4 * lcg(&mut seed), lcg(&mut seed).powi(3)]).collect();
    let n = notw(&pts, res, 4, true, 0, 0.0);
    let stats = |c: &[u32]| {
        let used: Vec<f64> = c.iter().filter(|&&v| v > 0).map(|&v| v as f64).collect();
        let m = used.iter().sum::<f64>() / used.len() as f64;
        let sd = (used.iter().map(|v| (v - m).powi(2)).sum::<f64>() / used.len() as f64).sqrt();
        (used.len() as f64 / c.len() as f64, sd / m)
    };
    let (u0, cv0) = stats(&n.counts);
    let (u1, cv1) = stats(&count_map(&pts, res, Some((&n.warp, true))));
    assert!(u1 > 2.0 * u0, "used {u0} -> {u1}");
    assert!(cv1 < 0.5 * cv0, "cv {cv0} -> {cv1}");
    // the row pass alone already evens out the columns inside each row
    let (ur, _) = stats(&n.counts_rows.iter().map(|&c| c.round() as u32).collect::<Vec<_>>());
    assert!(ur > 1.8 * u0, "rows only: used {u0} -> {ur}");
}

#[test]
fn the_final_warp_follows_equation_6() {
    let res = 8;
    let mut seed = 11u64;
    let pts: Vec<[f32; 2]> = (0..3000).map(|_| [lcg(&mut seed).powi(2), lcg(&mut seed)]).collect();
    let n = notw(&pts, res, 2, false, 0, 0.0);
    let (x, y) = (0.37f32, 0.81f32);
    let i = (y * res as f32) as usize;
    let xw = x + eval_offset(n.warp.row(i), x);
    let j = (xw * res as f32) as usize;
    let yw = y + eval_offset(&n.warp.column(j), y);
    assert_eq!(n.warp.apply(x, y), (xw, yw));
    // the column functions were built from the counts rebuilt through the row warps
    assert_eq!(n.counts_rows, rebuild_rows(&n.counts, &n.warp.ox, res));
}

#[test]
fn the_rebuilt_counts_spread_each_texel_over_its_image() {
    // one row of 4 texels; the row warp sends edge 1/4 to 1/2 and edge 2/4 to 3/4 (texel 0
    // magnified 2x, texel 1 kept, texels 2-3 squeezed into the last quarter)
    let res = 4;
    let mut counts = vec![0u32; 16];
    counts[..4].copy_from_slice(&[8, 2, 3, 5]);
    let mut ox = vec![0.0f32; 16];
    ox[..4].copy_from_slice(&[0.25, 0.25, 0.125, 0.0]);
    let rows = rebuild_rows(&counts, &ox, res);
    // texel 0 -> [0, 1/2]: half each to texels 0 and 1; texel 1 -> [1/2, 3/4]: texel 2;
    // texels 2 and 3 -> [3/4, 7/8] and [7/8, 1]: texel 3
    assert_eq!(&rows[..4], &[4.0, 4.0, 2.0, 8.0]);
    assert!(rows[4..].iter().all(|&c| c == 0.0));
    // samples spread evenly along each texel's row (40-99 a texel, at its centre height, so the
    // row function is its own): the second pass over them gives the same map to within one
    // sample at each end of a texel's image; a row's total is kept
    let res = 16;
    let mut seed = 5u64;
    let mut pts = Vec::new();
    for i in 0..res {
        for k in 0..res {
            let c = 40 + (lcg(&mut seed) * 60.0) as usize;
            let d = if k < 4 || i > 12 { 4 } else { 1 };
            for s in 0..c / d {
                pts.push([(k as f32 + (s as f32 + 0.5) / (c / d) as f32) / res as f32, (i as f32 + 0.5) / res as f32]);
            }
        }
    }
    let n = notw(&pts, res, 4, false, 0, 0.0);
    for i in 0..res {
        let (a, b): (f32, u32) = (n.counts_rows[i * res..(i + 1) * res].iter().sum(), n.counts[i * res..(i + 1) * res].iter().sum());
        assert!((a - b as f32).abs() <= 1e-3 * b as f32, "row {i}: {a} against {b}");
    }
    let second = count_map(&pts, res, Some((&n.warp, false)));
    for (t, (&a, &b)) in n.counts_rows.iter().zip(&second).enumerate() {
        assert!((a - b as f32).abs() <= 2.0, "texel {t}: rebuilt {a}, samples {b}");
    }
    let off: f32 = n.counts_rows.iter().zip(&second).map(|(&a, &b)| (a - b as f32).abs()).sum();
    assert!(off < 0.01 * pts.len() as f32, "the rebuilt map strays from the samples' by {off}");
}

#[test]
fn rtw_collapses_by_maximum() {
    let res = 8;
    let mut imp = vec![0.0f32; res * res];
    imp[2 * res + 1] = 5.0; // one important texel at column 1, row 2
    imp[6 * res + 6] = 1.0;
    let w = rtw(&imp, res, 0);
    // x density: columns 1 (5) and 6 (1): x' at the right edge of column 1 is 5/6
    assert!((w.warp_x(2.0 / 8.0, 0.9) - 5.0 / 6.0).abs() < 1e-6);
    // the same function in every row
    assert_eq!(w.warp_x(0.2, 0.1), w.warp_x(0.2, 0.9));
    let (_, y) = w.apply(0.1, 3.0 / 8.0);
    assert!((y - 5.0 / 6.0).abs() < 1e-6);
    // blur spreads importance to the neighbours
    assert_eq!(blur(&[0.0, 3.0, 0.0, 0.0], 1), vec![1.5, 1.0, 1.0, 0.0]);
    assert!((rtw_importance(2.0, 10.0, 1.0, 1.0) - 1.8).abs() < 1e-6);
}

#[test]
fn desired_view_bounds_the_points_with_a_margin() {
    let pts = [[0.25, 0.5], [0.75, 0.625], [0.5, 0.5]];
    let (lo, hi) = desired_view(&pts, 100, 2.0).unwrap();
    assert!((lo[0] - (0.25 - 0.01)).abs() < 1e-6 && (hi[0] - (0.75 + 0.01)).abs() < 1e-6);
    assert!((lo[1] - (0.5 - 0.0025)).abs() < 1e-6 && (hi[1] - (0.625 + 0.0025)).abs() < 1e-6);
    // a single point: one texel wide
    let (lo, hi) = desired_view(&[[0.5, 0.5]], 10, 0.0).unwrap();
    assert!((hi[0] - lo[0] - 0.1).abs() < 1e-6);
    assert!(desired_view(&[], 10, 1.0).is_none());
}

#[test]
fn interpolated_warp_is_continuous_across_rows() {
    let res = 16;
    let mut seed = 5u64;
    let pts: Vec<[f32; 2]> = (0..5000).map(|_| [lcg(&mut seed).powi(3), lcg(&mut seed)]).collect();
    let n = notw(&pts, res, 0, true, 0, 0.0);
    // crossing the boundary between rows 7 and 8 moves x' by (almost) nothing
    let (a, _) = n.warp.apply(0.4, 0.5 - 1e-5);
    let (b, _) = n.warp.apply(0.4, 0.5 + 1e-5);
    assert!((a - b).abs() < 1e-3, "{a} vs {b}");
    // at a row centre it is that row's function alone
    let y = 7.5 / 16.0;
    assert!((n.warp.warp_x(0.4, y) - (0.4 + eval_offset(n.warp.row(7), 0.4))).abs() < 1e-6);
    // eq. 6 as printed jumps there
    let e = notw(&pts, res, 0, false, 0, 0.0);
    let (a, _) = e.warp.apply(0.4, 0.5 - 1e-5);
    let (b, _) = e.warp.apply(0.4, 0.5 + 1e-5);
    assert!((a - b).abs() > 1e-3, "rows 7 and 8 happen to agree: the test needs other points");
}

#[test]
fn singular_values_by_hand() {
    // identity, a diagonal scale, a rotation (both 1) and a shear [[1, 1], [0, 1]] (golden ratio)
    let close = |a: (f32, f32), b: (f32, f32)| (a.0 - b.0).abs() < 1e-5 && (a.1 - b.1).abs() < 1e-5;
    assert!(close(singular_values([1.0, 0.0], [0.0, 1.0]), (1.0, 1.0)));
    assert!(close(singular_values([0.25, 0.0], [0.0, 3.0]), (0.25, 3.0)));
    let (c, s) = (0.6f32, 0.8f32);
    assert!(close(singular_values([2.0 * c, 2.0 * s], [-0.5 * s, 0.5 * c]), (0.5, 2.0)));
    let phi = (1.0 + 5f32.sqrt()) / 2.0;
    assert!(close(singular_values([1.0, 0.0], [1.0, 1.0]), (1.0 / phi, phi)));
    // rank one: a collapsed direction
    assert!(close(singular_values([1.0, 1.0], [2.0, 2.0]), (0.0, 10f32.sqrt())));
}

#[test]
fn gradient_footprint_by_hand() {
    let close = |a: Option<f32>, b: f32| (a.unwrap() - b).abs() < 1e-5;
    // texels of 0.1 m (10 texels per metre), no warp: 0.1 m in every direction
    let (a1, a2) = ([10.0, 0.0], [0.0, 10.0]);
    let id = ([1.0, 0.0], [0.0, 1.0]);
    assert!(close(gradient_footprint(a1, a2, id.0, id.1, [1.0, 0.0]), 0.1));
    assert!(close(gradient_footprint(a1, a2, id.0, id.1, [0.6, 0.8]), 0.1));
    // the warp magnifies x 4x and compresses y 2x: along x 0.025 m, along y 0.2 m, whereas the
    // isotropic mode 0 takes 0.1 / (smallest singular value 0.5) = 0.2 m for both
    let (j0, j1) = ([4.0, 0.0], [0.0, 0.5]);
    assert!(close(gradient_footprint(a1, a2, j0, j1, [1.0, 0.0]), 0.025));
    assert!(close(gradient_footprint(a1, a2, j0, j1, [0.0, 1.0]), 0.2));
    // a rotated crop (A a rotation by 90 degrees): the magnified map axis is world y
    assert!(close(gradient_footprint([0.0, 10.0], [-10.0, 0.0], j0, j1, [0.0, 1.0]), 0.025));
    // a shear [[1, 1], [0, 1]]: a warped texel spans (1, 0) and (-1, 1) cropped texels, extent
    // along x sqrt(1 + 1) = 1.414 texels (|J^-T m| with J^-T = [[1, 0], [-1, 1]])
    assert!(close(gradient_footprint(a1, a2, [1.0, 0.0], [1.0, 1.0], [1.0, 0.0]), 0.1 * 2f32.sqrt()));
    // singular warp or projection
    assert!(gradient_footprint(a1, a2, [1.0, 1.0], [2.0, 2.0], [1.0, 0.0]).is_none());
    assert!(gradient_footprint([1.0, 0.0], [2.0, 0.0], id.0, id.1, [1.0, 0.0]).is_none());
}
