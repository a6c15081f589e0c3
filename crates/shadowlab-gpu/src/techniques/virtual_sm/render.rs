//! `virtual`'s page rendering. Pass 1 draws the static copies the frame fills (static chunks
//! only) into their slots of the static pool; pass 2 builds every rendered page in its atlas
//! slot: a page drawn whole is cleared and gets every chunk over it; a page with a static copy
//! gets the copy (copy.wgsl) and then the moving chunks over it.

use shadowlab_core::techniques::virtual_sm::Build;

use super::draw::page_draws;
use super::gpu::VirtualShadows;
use crate::record::Recorder;
use crate::technique::FrameInputs;

/// One pass over `target` that, per page `(instance, origin)` in `slots`, sets the page's
/// viewport and runs `draw` (which binds its own pipelines).
fn page_pass(
    rec: &mut Recorder,
    stage: &str,
    target: &wgpu::Texture,
    t: &VirtualShadows,
    f: &FrameInputs,
    slots: &[(u32, (u32, u32))],
    mut draw: impl FnMut(&mut wgpu::RenderPass<'_>, u32),
) {
    let view = target.create_view(&Default::default());
    let pr = t.page_res;
    rec.stage(stage, |enc| {
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(stage),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &view,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(0, &t.page_group, &[]);
        pass.set_bind_group(1, &f.scene.group, &[]);
        for &(i, (x, y)) in slots {
            pass.set_viewport(x as f32, y as f32, pr as f32, pr as f32, 0.0, 1.0);
            pass.set_scissor_rect(x, y, pr, pr);
            draw(&mut pass, i);
        }
    });
}

/// Draws triangle ranges with instance `i` (page i's view-projection).
fn draw_ranges(pass: &mut wgpu::RenderPass<'_>, ranges: &[(u32, u32)], i: u32) -> u64 {
    for &(a, b) in ranges {
        pass.draw(a * 3..b * 3, i..i + 1);
    }
    ranges.iter().map(|&(a, b)| (b - a) as u64).sum()
}

pub(super) fn render(t: &mut VirtualShadows, f: &FrameInputs, rec: &mut Recorder) {
    t.triangles_drawn = 0;
    let (Some(c), false) = (&t.clipmap, t.alloc.render.is_empty()) else { return };
    let (pr, m0) = (t.page_res, t.dynamic_chunk0);
    let origin = |slot: u32, cols: u32| ((slot % cols) * pr, (slot / cols) * pr);
    // per rendered page: the chunks of pass 1 (static copy) and of pass 2
    let mut fills = Vec::new();
    let mut draws = Vec::new();
    for (i, ((k, _), b)) in t.alloc.render.iter().zip(&t.builds).enumerate() {
        match b {
            Build::Full => draws.push(page_draws(&t.chunks, c, k)),
            Build::Fill(s) => {
                fills.push((i as u32, origin(*s, t.static_cols), page_draws(&t.chunks[..m0], c, k)));
                draws.push(page_draws(&t.chunks[m0..], c, k));
            }
            Build::Copy(_) => draws.push(page_draws(&t.chunks[m0..], c, k)),
        }
    }
    let mut triangles = 0;
    if !fills.is_empty() {
        let slots: Vec<(u32, (u32, u32))> = fills.iter().map(|(i, o, _)| (*i, *o)).collect();
        page_pass(rec, "virtual.render_static", &t.static_atlas, t, f, &slots, |pass, i| {
            pass.set_pipeline(&t.clear_pipeline);
            pass.draw(0..3, 0..1);
            pass.set_pipeline(&t.page_pipeline);
            let (_, _, ranges) = fills.iter().find(|e| e.0 == i).expect("a fill per slot");
            triangles += draw_ranges(pass, ranges, i);
        });
    }
    let slots: Vec<(u32, (u32, u32))> = t.alloc.render.iter().enumerate().map(|(i, (_, s))| (i as u32, origin(*s, t.cols))).collect();
    page_pass(rec, "virtual.render", &t.atlas, t, f, &slots, |pass, i| {
        if t.builds[i as usize] == Build::Full {
            pass.set_pipeline(&t.clear_pipeline);
            pass.draw(0..3, 0..1);
        } else {
            pass.set_pipeline(&t.copy_pipeline);
            pass.set_bind_group(0, &t.copy_group, &[]);
            pass.draw(0..3, i..i + 1);
            pass.set_bind_group(0, &t.page_group, &[]);
        }
        pass.set_pipeline(&t.page_pipeline);
        triangles += draw_ranges(pass, &draws[i as usize], i);
    });
    t.triangles_drawn = triangles;
}
