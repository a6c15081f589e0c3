//! Shadow-map warping on the CPU: the reference for the GPU passes of `notw`, `rtw` and
//! `notw-dv` (shadowlab-gpu `techniques/warp`), generic over one square 2D map so that point
//! lights can reuse it per cube face / paraboloid.
//!
//! Coordinates are map coordinates in [0,1]^2 (x = column, y = row, texel (k, i) covers
//! [k/w, (k+1)/w) x [i/w, (i+1)/w)), taken after the desired-view crop.
//!
//! A 1D warping function is stored as `w` offsets o at the texel *right edges* x = (k+1)/w
//! (o(0) = 0 is implicit; o(1) = 0 always): for counts, o((k+1)/w) = g((k+1)/w)/N - (k+1)/w with
//! g the prefix sum (seed 000 eq. 4; seed 002 eq. 4.4). Between edges the offset is linear, so
//! x + o(x) is exactly the piecewise-linear CDF of the per-texel counts: monotonic, onto [0,1].
//! Rows with no samples get the identity (o = 0).

/// Inclusive prefix sum of every row of a `rows x len` array (the GPU `prefix_sum` reference).
pub fn row_prefix(values: &[f32], rows: usize, len: usize) -> Vec<f32> {
    let mut out = vec![0.0; rows * len];
    for r in 0..rows {
        let mut acc = 0.0f32;
        for k in 0..len {
            acc += values[r * len + k];
            out[r * len + k] = acc;
        }
    }
    out
}

/// Offsets at the right edges of the texels of one row from its inclusive prefix sum (eq. 4).
pub fn offsets_from_prefix(prefix: &[f32]) -> Vec<f32> {
    let w = prefix.len();
    let n = prefix.last().copied().unwrap_or(0.0);
    prefix.iter().enumerate().map(|(k, &g)| if n > 0.0 { g / n - (k + 1) as f32 / w as f32 } else { 0.0 }).collect()
}

/// o(x) of one stored function (`o.len()` = w edge offsets), linear between edges, 0 outside [0,1].
pub fn eval_offset(o: &[f32], x: f32) -> f32 {
    let w = o.len();
    if w == 0 || !(0.0..1.0).contains(&x) {
        return 0.0;
    }
    let s = x * w as f32;
    let k = (s.floor() as usize).min(w - 1);
    let t = s - k as f32;
    let left = if k == 0 { 0.0 } else { o[k - 1] };
    left + (o[k] - left) * t
}

/// Weighted average of neighbouring functions (seed 000 section 3.1, Figure 4): function i
/// becomes the average of functions j in [i - window/2, i + window/2], weighted by their sample
/// totals. A convex combination of monotonic warps is monotonic. `window` 0: unchanged.
/// `tent`: each function's weight also falls off linearly with |i - j| (window/2 + 1 - |i - j|),
/// so a function with many samples enters the average gradually instead of at once: with the
/// box (the seeds'), neighbouring functions differ by a step wherever a heavy function enters
/// or leaves the window, which sparse samples make large.
pub fn smooth(offsets: &[f32], totals: &[f32], len: usize, window: usize, tent: bool) -> Vec<f32> {
    let rows = totals.len();
    let half = window / 2;
    let mut out = vec![0.0; rows * len];
    for i in 0..rows {
        let (a, b) = (i.saturating_sub(half), (i + half).min(rows - 1));
        let weight = |j: usize| if tent { (half + 1 - i.abs_diff(j)) as f32 * totals[j] } else { totals[j] };
        let wsum: f32 = (a..=b).map(weight).sum();
        if wsum <= 0.0 {
            continue;
        }
        for k in 0..len {
            let s: f32 = (a..=b).map(|j| weight(j) * offsets[j * len + k]).sum();
            out[i * len + k] = s / wsum;
        }
    }
    out
}

/// Per-row warping functions of a `res x res` count map (row-major), smoothed over `window`.
/// Returns the `res x res` offsets (row i, edge k at i*res+k) and the row totals.
pub fn row_warps(counts: &[f32], res: usize, window: usize, tent: bool) -> Vec<f32> {
    let prefix = row_prefix(counts, res, res);
    let totals: Vec<f32> = (0..res).map(|r| prefix[r * res + res - 1]).collect();
    let raw: Vec<f32> = (0..res).flat_map(|r| offsets_from_prefix(&prefix[r * res..(r + 1) * res])).collect();
    smooth(&raw, &totals, res, window, tent)
}

fn texel(v: f32, res: usize) -> usize {
    ((v * res as f32).floor().max(0.0) as usize).min(res - 1)
}

/// A 2D warp of one square map: `ox` holds `rows_x` row functions (1 = the same for every
/// row, RTW), `oy` holds `cols_y` column functions stored column-major as an image: edge k of
/// column j at `k * cols_y + j` (the layout of the GPU textures, `res` wide or 1 wide).
#[derive(Clone, Debug, PartialEq)]
pub struct Warp2D {
    pub res: usize,
    pub rows_x: usize,
    pub cols_y: usize,
    pub ox: Vec<f32>,
    pub oy: Vec<f32>,
    /// Offsets interpolated linearly between the two nearest functions (centres at
    /// (i + 0.5) / w): a continuous warp. False: eq. 6 as printed (function floor(v w)).
    pub interp: bool,
}

/// Nearest functions (i0, i1) and the weight of i1 at coordinate v (shared with params.wgsl).
pub fn neighbours(v: f32, res: usize, interp: bool) -> (usize, usize, f32) {
    if !interp {
        let i = texel(v, res);
        return (i, i, 0.0);
    }
    let s = (v * res as f32 - 0.5).clamp(0.0, (res - 1) as f32);
    let i0 = s.floor();
    (i0 as usize, (i0 as usize + 1).min(res - 1), s - i0)
}

impl Warp2D {
    pub fn identity(res: usize) -> Warp2D {
        Warp2D { res, rows_x: 1, cols_y: 1, ox: vec![0.0; res], oy: vec![0.0; res], interp: true }
    }

    /// Row function i's offsets.
    pub fn row(&self, i: usize) -> &[f32] {
        let i = i.min(self.rows_x - 1);
        &self.ox[i * self.res..(i + 1) * self.res]
    }

    /// Column function j's offsets (copied out of the image layout).
    pub fn column(&self, j: usize) -> Vec<f32> {
        let j = j.min(self.cols_y - 1);
        (0..self.res).map(|k| self.oy[k * self.cols_y + j]).collect()
    }

    /// x' of the row pass: x + o_x^(i)(x), i = floor(y w) (or interpolated).
    pub fn warp_x(&self, x: f32, y: f32) -> f32 {
        let (a, b, t) = neighbours(y, self.res, self.interp);
        let (oa, ob) = (eval_offset(self.row(a), x), eval_offset(self.row(b), x));
        x + (oa + (ob - oa) * t)
    }

    /// Seed 000 eq. 6: (x + o_x^(i)(x), y + o_y^(j)(y)), i = floor(y w), j = floor(x' w).
    /// Points outside [0,1]^2 keep the offsets of the border functions (0 along the axis).
    pub fn apply(&self, x: f32, y: f32) -> (f32, f32) {
        let xw = self.warp_x(x, y);
        let (a, b, t) = neighbours(xw, self.res, self.interp);
        let (oa, ob) = (eval_offset(&self.column(a), y), eval_offset(&self.column(b), y));
        (xw, y + (oa + (ob - oa) * t))
    }
}

/// The x (increasing in [0,1]) where the monotonic piecewise-linear f, with f(0) = 0, f(1) = 1
/// and one kink per texel edge k / res (`f(k)` gives its value there), reaches `target`:
/// bisection over the edges, then the linear segment solved exactly. Outside [0,1) f is the
/// identity (the offsets vanish there). The GPU `invert_pl` in lookup.wgsl.
pub fn invert_pl(f: impl Fn(usize) -> f32, res: usize, target: f32) -> f32 {
    if !(0.0..1.0).contains(&target) {
        return target;
    }
    // invariant: f(lo) <= target < f(hi) (edge indices)
    let (mut lo, mut hi) = (0usize, res);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if f(mid) <= target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let (a, b) = (f(lo), f(hi));
    let t = if b > a { ((target - a) / (b - a)).clamp(0.0, 1.0) } else { 0.0 };
    (lo as f32 + t) / res as f32
}

impl Warp2D {
    /// The exact inverse of `apply` (no iteration): the column pass y' = y + o_y(y) uses the
    /// functions at x', which the target gives, so y is one 1D inversion; then the row pass
    /// x' = x + o_x(x) uses the functions at y, so x is another. Both 1D functions are
    /// monotonic and piecewise linear with kinks only at texel edges (the interpolation weight
    /// between functions is fixed by the other coordinate).
    pub fn unapply(&self, xw: f32, yw: f32) -> (f32, f32) {
        let res = self.res;
        let edge = |o: &dyn Fn(f32) -> f32, k: usize| {
            let x = k as f32 / res as f32;
            if k >= res {
                1.0
            } else {
                x + o(x)
            }
        };
        let (a, b, t) = neighbours(xw, res, self.interp);
        let (ca, cb) = (self.column(a), self.column(b));
        let oy = |y: f32| {
            let (p, q) = (eval_offset(&ca, y), eval_offset(&cb, y));
            p + (q - p) * t
        };
        let y = invert_pl(|k| edge(&oy, k), res, yw);
        let (a, b, t) = neighbours(y, res, self.interp);
        let ox = |x: f32| {
            let (p, q) = (eval_offset(self.row(a), x), eval_offset(self.row(b), x));
            p + (q - p) * t
        };
        (invert_pl(|k| edge(&ox, k), res, xw), y)
    }
}

/// Sample counts per texel of `points`, optionally after the row pass only or the full warp.
pub fn count_map(points: &[[f32; 2]], res: usize, warp: Option<(&Warp2D, bool)>) -> Vec<u32> {
    let mut c = vec![0u32; res * res];
    for &[x, y] in points {
        let (x, y) = match warp {
            None => (x, y),
            Some((w, false)) => (w.warp_x(x, y), y),
            Some((w, true)) => w.apply(x, y),
        };
        if (0.0..1.0).contains(&x) && (0.0..1.0).contains(&y) {
            c[texel(y, res) * res + texel(x, res)] += 1;
        }
    }
    c
}

/// Every stage of the NoTW construction (seed 000 section 3, steps 2-7), kept for the report.
pub struct Notw {
    pub counts: Vec<u32>,
    /// The counts rebuilt through the row warps ([`rebuild_rows`]).
    pub counts_rows: Vec<f32>,
    pub warp: Warp2D,
}

/// The count map rebuilt through row warps (step 6) from the counts alone: each texel's count is
/// spread evenly over its image [x'(k / res), x'((k + 1) / res)] under its own row's function
/// (`ox`, row-major offsets at the right edges), each texel it covers taking its overlap's
/// share. It takes a texel's samples as spread evenly over it, which is what the
/// piecewise-linear warp assumes; a second pass over the samples (`count_map` through the rows)
/// would cost as much as the first. The GPU `rebuild` in analyze.wgsl, in the same order.
pub fn rebuild_rows(counts: &[u32], ox: &[f32], res: usize) -> Vec<f32> {
    let mut out = vec![0.0f32; res * res];
    let fw = res as f32;
    for i in 0..res {
        let row = &mut out[i * res..(i + 1) * res];
        let mut x0 = 0.0f32;
        for k in 0..res {
            let x1 = if k + 1 == res { 1.0 } else { (k + 1) as f32 / fw + ox[i * res + k] };
            let c = counts[i * res + k] as f32;
            if c > 0.0 {
                let (ja, jb) = (texel(x0, res), texel(x1, res));
                if ja == jb || x1 <= x0 {
                    row[ja] += c;
                } else {
                    for (j, r) in row.iter_mut().enumerate().take(jb + 1).skip(ja) {
                        let part = x1.min((j + 1) as f32 / fw) - x0.max(j as f32 / fw);
                        *r += c * part.max(0.0) / (x1 - x0);
                    }
                }
            }
            x0 = x1;
        }
    }
    out
}

/// NoTW on points in map coordinates: count map, row warps (smoothed over `window` rows
/// weighted by their totals), the count map rebuilt through them ([`rebuild_rows`]), column warps (smoothed over
/// `window` columns), the final warp of eq. 6 (`interp`: offsets interpolated between
/// neighbouring functions). `blur` > 0 box-blurs the counts along each row (column) first;
/// `mix` adds a uniform floor of `mix` x the mean count per texel (points / res^2) to each.
pub fn notw(points: &[[f32; 2]], res: usize, window: usize, interp: bool, blur_radius: usize, mix: f32) -> Notw {
    notw_shaped(points, res, window, false, interp, blur_radius, mix)
}

/// [`notw`] with the smoothing window's shape: `tent` or the seeds' box (see [`smooth`]).
pub fn notw_shaped(points: &[[f32; 2]], res: usize, window: usize, tent: bool, interp: bool, blur_radius: usize, mix: f32) -> Notw {
    let floor = mix * points.len() as f32 / (res * res) as f32;
    let blur_rows = |v: Vec<f32>| -> Vec<f32> { v.chunks(res).flat_map(|r| blur(r, blur_radius)).map(|c| c + floor).collect() };
    let counts = count_map(points, res, None);
    let cf = blur_rows(counts.iter().map(|&c| c as f32).collect());
    let ox = row_warps(&cf, res, window, tent);
    let counts_rows = rebuild_rows(&counts, &ox, res);
    // columns: transpose, warp as rows, transpose back into the image layout
    let t = blur_rows((0..res * res).map(|idx| counts_rows[(idx % res) * res + idx / res]).collect());
    let oy_t = row_warps(&t, res, window, tent);
    let oy: Vec<f32> = (0..res * res).map(|idx| oy_t[(idx % res) * res + idx / res]).collect();
    Notw { counts, counts_rows, warp: Warp2D { res, rows_x: res, cols_y: res, ox, oy, interp } }
}

/// Box blur of half-width `radius` (clamped at the ends, normalised by the taps inside).
pub fn blur(v: &[f32], radius: usize) -> Vec<f32> {
    let n = v.len();
    (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(radius), (i + radius).min(n - 1));
            v[a..=b].iter().sum::<f32>() / (b - a + 1) as f32
        })
        .collect()
}

/// RTW's two 1D functions (Rosen 2012, seed 002 Algorithm 1): the `res x res` importance map
/// collapsed by maximum per column (-> warp of x) and per row (-> warp of y), blurred with
/// `radius`, turned into warps like counts (the importance is the density).
pub fn rtw(importance: &[f32], res: usize, radius: usize) -> Warp2D {
    let colmax: Vec<f32> = (0..res).map(|k| (0..res).map(|i| importance[i * res + k]).fold(0.0, f32::max)).collect();
    let rowmax: Vec<f32> = (0..res).map(|i| importance[i * res..(i + 1) * res].iter().copied().fold(0.0, f32::max)).collect();
    let fx = offsets_from_prefix(&row_prefix(&blur(&colmax, radius), 1, res));
    let fy = offsets_from_prefix(&row_prefix(&blur(&rowmax, radius), 1, res));
    Warp2D { res, rows_x: 1, cols_y: 1, ox: fx, oy: fy, interp: true }
}

/// RTW importance of one view sample (GUIDE: the desired-view mask plus the distance-to-eye
/// term (max distance - distance) / max distance); the map keeps the maximum per texel.
pub fn rtw_importance(distance: f32, max_distance: f32, w_dv: f32, w_eye: f32) -> f32 {
    w_dv + w_eye * ((max_distance - distance) / max_distance.max(1e-20)).clamp(0.0, 1.0)
}

/// The desired view: the bounding rectangle of `points` (clamped to [0,1]) grown by `margin`
/// texels of a `res` map on every side (at least one texel wide). None without points.
pub fn desired_view(points: &[[f32; 2]], res: usize, margin: f32) -> Option<([f32; 2], [f32; 2])> {
    if points.is_empty() {
        return None;
    }
    let mut lo = [1.0f32; 2];
    let mut hi = [0.0f32; 2];
    for p in points {
        for a in 0..2 {
            lo[a] = lo[a].min(p[a].clamp(0.0, 1.0));
            hi[a] = hi[a].max(p[a].clamp(0.0, 1.0));
        }
    }
    Some(grow_rect(lo, hi, res, margin))
}

/// The margin rule shared with the GPU: extent e = max(hi - lo, 1/res); grow by margin * e / res.
pub fn grow_rect(lo: [f32; 2], hi: [f32; 2], res: usize, margin: f32) -> ([f32; 2], [f32; 2]) {
    let mut a = lo;
    let mut b = hi;
    for i in 0..2 {
        let e = (hi[i] - lo[i]).max(1.0 / res as f32);
        let m = margin * e / res as f32;
        a[i] = lo[i] - m;
        b[i] = lo[i] + e + m;
    }
    (a, b)
}

/// Singular values (smallest, largest) of the 2x2 matrix with columns `a` and `b` (the warp's
/// Jacobian from finite differences; the GPU `singular_values` in eval.wgsl).
pub fn singular_values(a: [f32; 2], b: [f32; 2]) -> (f32, f32) {
    let e = a[0] * a[0] + a[1] * a[1];
    let g = b[0] * b[0] + b[1] * b[1];
    let f = a[0] * b[0] + a[1] * b[1];
    let tr = 0.5 * (e + g);
    let det = e * g - f * f;
    let d = (tr * tr - det).max(0.0).sqrt();
    ((tr - d).max(0.0).sqrt(), (tr + d).max(0.0).sqrt())
}

/// World extent along the unit direction `m` of one warped texel (eval.wgsl
/// `gradient_footprint`, bias mode 2). `a1`, `a2`: cropped texels per metre along two
/// orthonormal world directions across the light (the columns of A); `j0`, `j1`: the warp's
/// Jacobian columns (warped per cropped); `m`: the receiver's depth-gradient direction in that
/// world basis. One warped texel spans the columns of M = A^-1 J^-1 metres; its extent along m
/// is |M^T m| = |J^-T A^-T m|. None when A or J is singular.
pub fn gradient_footprint(a1: [f32; 2], a2: [f32; 2], j0: [f32; 2], j1: [f32; 2], m: [f32; 2]) -> Option<f32> {
    // solve X^T y = v for the 2x2 matrix X with columns c0, c1
    let solve_t = |c0: [f32; 2], c1: [f32; 2], v: [f32; 2]| {
        let det = c0[0] * c1[1] - c1[0] * c0[1];
        (det.abs() > 1e-12).then(|| [(c1[1] * v[0] - c0[1] * v[1]) / det, (-c1[0] * v[0] + c0[0] * v[1]) / det])
    };
    let y = solve_t(a1, a2, m)?;
    let z = solve_t(j0, j1, y)?;
    Some((z[0] * z[0] + z[1] * z[1]).sqrt())
}

#[cfg(test)]
#[path = "warp_tests.rs"]
mod tests;

#[cfg(test)]
#[path = "warp_kinks_tests.rs"]
mod kinks_tests;
