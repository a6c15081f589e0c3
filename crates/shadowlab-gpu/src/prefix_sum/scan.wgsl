// Inclusive prefix sums of many runs at once (one workgroup per run): run r, element k is at
// in_base + r * row_step + k * elem_step in `scan_in` (u32 values, or f32 bits when input_f32),
// written as f32 at out_base + the same offset in `scan_out`. Rows of a row-major w x h map:
// row_step w, elem_step 1; its columns: row_step 1, elem_step w. Hillis-Steele in shared memory
// over chunks of 256 with a running carry. Sums of integers below 2^24 are exact.

struct ScanParams {
    rows: u32,
    len: u32,
    row_step: u32,
    elem_step: u32,
    in_base: u32,
    out_base: u32,
    input_f32: u32,
    _pad: u32,
}

@group(0) @binding(0) var<uniform> sp: ScanParams;
@group(0) @binding(1) var<storage, read> scan_in: array<u32>;
@group(0) @binding(2) var<storage, read_write> scan_out: array<f32>;

const SCAN_GROUP: u32 = 256u;
var<workgroup> tile: array<f32, 256>;

@compute @workgroup_size(256)
fn scan_rows(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) t: u32) {
    let r = wg.y * 65535u + wg.x;
    if r >= sp.rows {
        return;
    }
    var carry = 0.0;
    for (var base = 0u; base < sp.len; base += SCAN_GROUP) {
        let k = base + t;
        let off = r * sp.row_step + k * sp.elem_step;
        var v = 0.0;
        if k < sp.len {
            let raw = scan_in[sp.in_base + off];
            v = select(f32(raw), bitcast<f32>(raw), sp.input_f32 != 0u);
        }
        tile[t] = v;
        workgroupBarrier();
        for (var d = 1u; d < SCAN_GROUP; d <<= 1u) {
            var add = 0.0;
            if t >= d {
                add = tile[t - d];
            }
            workgroupBarrier();
            tile[t] += add;
            workgroupBarrier();
        }
        if k < sp.len {
            scan_out[sp.out_base + off] = tile[t] + carry;
        }
        carry += tile[SCAN_GROUP - 1u];
        workgroupBarrier();
    }
}
