//! What FLIP costs on the CPU: one image pair alone (median of `repeat`), and `k` pairs through
//! `flip_each` (rayon, as a compare frame runs its techniques).
//! `cargo run --release -p shadowlab-core --example flip_cost [reference.png test.png] [repeat] [k]`
//! (without images: a synthetic 1024x1024 pair, a grey floor with shadowed squares moved by a
//! few pixels).

use std::time::Instant;

use shadowlab_core::flip::{flip_each, flip_rgba8};

fn synthetic(w: u32, h: u32, shift: u32) -> Vec<u8> {
    let mut px = Vec::with_capacity((w * h * 4) as usize);
    for y in 0..h {
        for x in 0..w {
            let shadowed = ((x + shift) / 96 + y / 96) % 3 == 0;
            let v = if shadowed { 60 } else { 190 } as u8;
            px.extend_from_slice(&[v, (v as u32 * 9 / 10) as u8, (v as u32 * 8 / 10) as u8, 255]);
        }
    }
    px
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let images = args.len() >= 3 && args[1].ends_with(".png");
    let (w, h, r, t) = if images {
        let load = |p: &str| image::open(p).unwrap_or_else(|e| panic!("{p}: {e}")).into_rgba8();
        let (r, t) = (load(&args[1]), load(&args[2]));
        (r.width(), r.height(), r.into_raw(), t.into_raw())
    } else {
        (1024, 1024, synthetic(1024, 1024, 0), synthetic(1024, 1024, 3))
    };
    let rest = if images { &args[3..] } else { &args[1..] };
    let repeat: usize = rest.first().and_then(|s| s.parse().ok()).unwrap_or(5);
    let k: usize = rest.get(1).and_then(|s| s.parse().ok()).unwrap_or(8);
    let mut one = Vec::new();
    let mut mean = 0.0;
    for _ in 0..repeat {
        let t0 = Instant::now();
        mean = flip_rgba8(&r, &t, w, h).mean();
        one.push(t0.elapsed().as_secs_f64() * 1e3);
    }
    let tests: Vec<&[u8]> = (0..k).map(|_| t.as_slice()).collect();
    let t0 = Instant::now();
    let maps = flip_each(&r, &tests, w, h);
    let par = t0.elapsed().as_secs_f64() * 1e3;
    assert!(maps.iter().all(|m| m.mean() == mean));
    let t0 = Instant::now();
    let _ = flip_rgba8(&r, &r, w, h);
    let equal = t0.elapsed().as_secs_f64() * 1e3;
    println!("{w}x{h}: mean FLIP {mean:.6}");
    println!("one pair: {:.0} ms (median of {repeat}), {} rayon threads", median(one), rayon::current_num_threads());
    println!("{k} pairs through flip_each: {par:.0} ms ({:.0} ms per pair)", par / k as f64);
    println!("equal images (no computation): {equal:.2} ms");
}
