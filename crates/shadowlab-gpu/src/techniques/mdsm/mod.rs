//! `mdsm`: multiple-depth shadow maps with PCF(k, n) (seed 003, Pagot, Comba, Oliveira 2004).
//!
//! Three passes: the base depth map (exactly `sm`'s depth pass and projection; post-projective
//! depth, 0 = near the light), a selection compute pass that writes the n sorted depths of
//! every texel into one RGBA32F texel (`select.wgsl`, the WGSL twin of
//! [`shadowlab_core::techniques::mdsm::select`]), and the evaluation (`eval.wgsl`): `sm`'s bias model, then
//! k taps on a sqrt(k) x sqrt(k) grid, one fetch and one n-shadow test each
//! ([`shadowlab_core::techniques::mdsm::n_shadow_test`]), averaged to a lit fraction in steps of 1/(nk).
//! With n = 1 the selection is a copy (search width 1) and PCF(k, 1) is `sm:pcf=sqrt(k)`.

use bytemuck::{Pod, Zeroable};
use shadowlab_core::light::Light;
use shadowlab_core::lightspace;
use shadowlab_core::metrics::sampling_stats;
use shadowlab_core::params::family::{self, Bias};
use shadowlab_core::params::{Block, ParamDef, ParamSet, ParamTable};
use shadowlab_core::techniques::mdsm::{max_distinct, pcf_width, search_width, Select, DEFAULT_Q, MAX_DEPTHS, PCF_TAPS, SEARCH_SIZES};

use crate::record::Recorder;
use crate::scene_gpu::GpuScene;
use crate::shaders::compose;
use crate::technique::{compose_view, counted_evaluation, view_layout, FrameInputs, Technique, TechniqueInfo, TechniqueReport};
use crate::techniques::pictures::{count_image, depth_image};
use crate::techniques::sm::{self, DepthPass, SmParams};
use crate::{binding, Gpu, GpuError};

const SELECT_WGSL: &str = include_str!("select.wgsl");
const EVAL_WGSL: &str = include_str!("eval.wgsl");

pub fn shaders() -> Vec<(&'static str, String)> {
    vec![("mdsm/select.wgsl", compose(SELECT_WGSL, false)), ("mdsm/eval.wgsl", eval_src())]
}

/// eval.wgsl after `sm`'s bias model and sample counting (sm/bias.wgsl).
fn eval_src() -> String {
    compose_view(&format!("{}{EVAL_WGSL}", sm::BIAS_WGSL), false)
}

/// Depths per texel. Seed 003 demonstrates 2 and 3; 2 doubles the outcomes of every kernel
/// (Table 1) for one more channel. 1 = plain `sm`; 4 fills the RGBA32F texel.
pub const DEFAULT_N: f64 = 2.0;
/// PCF taps. 9 (3x3) is the paper's recommended pairing with a 2-SM (PCF(9,2) vs PCF(16,1)).
pub const DEFAULT_K: f64 = 9.0;
shadowlab_core::param_set! {
    /// `mdsm`'s parameters.
    pub struct MdsmSettings {
        pub res: u32 = family::RES.with_doc("shadow map side (texels)"),
        pub n: u32 = ParamDef::integer(
            "n",
            DEFAULT_N,
            1.0,
            MAX_DEPTHS as f64,
            "depths per texel (1 = sm); the n-shadow test gives n+1 levels per tap",
            "seed 003 sections 4.2-4.4 (2-SM, 3-SM; 4 fill one RGBA32F texel)",
        ),
        pub k: u32 = ParamDef::integer(
            "k",
            DEFAULT_K,
            1.0,
            25.0,
            "PCF taps, one of 1, 4, 9, 16, 25 (sqrt(k) x sqrt(k) grid one texel apart, centred on the sample)",
            "seed 003 Table 1, Figures 6-7 (PCF 2x2, 3x3, 4x4)",
        ),
        pub select: Select = ParamDef::choice(
            "select",
            Select::NAMES,
            0,
            "how the extra depths are chosen: minmax (region extremes, O(q)) or sort (medians of n groups, O(q log q))",
            "seed 003 section 4.3; section 5 uses min and max",
        ),
        pub q: u32 = ParamDef::integer(
            "q",
            DEFAULT_Q as f64,
            9.0,
            81.0,
            "search region samples, one of 9, 25, 49, 81 (centred square); larger: wider soft zone, more selection cost",
            "seed 003 section 6 cost example implies q = 9 (f > 1.28 x 512^2 with r = 7)",
        ),
        pub bias: Bias = Block::as_declared()
            .with(family::MAX_SLOPE.with_doc("clamp on tan(angle to light) for the slope, kernel and region bias")),
        pub region_bias: bool = ParamDef::flag(
            "region_bias",
            true,
            "add (sqrt(q)-1)/2 x tan texels of bias for the search region (n > 1); false: sloped lit surfaces self-shadow by up to 1/n",
            "receiver-plane bias (Isidoro 2006) extended to the search region; shadowlab measurement (docs/bench/mdsm.md)",
        ),
    }
    rules {
        fn validate(&self) -> Result<(), String> {
            let (k, q) = (self.k, self.q);
            pcf_width(k).ok_or_else(|| format!("k={k} is not one of {PCF_TAPS:?} (square PCF grids)"))?;
            search_width(q).ok_or_else(|| format!("q={q} is not one of {SEARCH_SIZES:?} (centred square regions)"))?;
            Ok(())
        }
        fn ineffective(&self) -> Vec<(&'static str, String)> {
            if self.n > 1 {
                return vec![];
            }
            let why = || "with n=1 there is no extra depth to select (the map is sm's)".to_string();
            vec![("select", why()), ("q", why()), ("region_bias", why())]
        }
    }
}

pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "mdsm",
    summary: "multiple-depth shadow map: n sorted depths per texel (RGBA32F) from a q-sample region, PCF(k,n) with the n-shadow test",
    cost: "sm's depth pass + a selection pass of q fetches per texel + k fetches per pixel",
    quality: "up to nk+1 shadow levels from k fetches; soft zone about sqrt(q) texels wider than the kernel",
    source: "Pagot, Comba, Oliveira 2004 (seed 003)",
    lights: &["directional", "spot"],
    params: ParamTable::of::<MdsmSettings>(),
    stalls: "",
    needs: "",
    storage_buffers: 8,
    compare: &[""],
    shaders,
    create: |gpu, scene, p, light| Ok(Box::new(MultiDepthMap::new(gpu, scene, &MdsmSettings::from_values(p), light)?)),
};

/// WGSL `MdsmParams` (select.wgsl and eval.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct MdsmParams {
    pub light_view_proj: [[f32; 4]; 4],
    /// texel world size, perspective flag, resolution, PCF grid width sqrt(k)
    pub texel: [f32; 4],
    /// constant bias, slope bias, normal offset (texels), max slope
    pub bias: [f32; 4],
    /// Depths per texel.
    pub n: u32,
    /// Search width sqrt(q) (1 when n = 1).
    pub region: u32,
    /// `select`'s index in `Select::NAMES`.
    pub select: u32,
    /// 1 if the slope bias covers the search region.
    pub region_bias: u32,
}

pub struct MultiDepthMap {
    pub(crate) groups: crate::binding::GroupCache,
    res: u32,
    k: u32,
    n: u32,
    params: MdsmParams,
    /// `sm`'s depth pass: the base map.
    depth: DepthPass,
    nsm: wgpu::Texture,
    /// Its view for the evaluation (made once: the bind group is kept).
    nsm_view: wgpu::TextureView,
    counts: wgpu::Buffer,
    uniform: wgpu::Buffer,
    select_pipeline: wgpu::ComputePipeline,
    select_group: wgpu::BindGroup,
    /// The evaluation and its analysis variant.
    eval: crate::technique::EvalPipelines,
    eval_layout: wgpu::BindGroupLayout,
}

impl MultiDepthMap {
    /// `p` has passed its rules (`k` and `q` are square counts; the table bounds `n`).
    pub fn new(gpu: &Gpu, scene: &GpuScene, p: &MdsmSettings, light: &Light) -> Result<MultiDepthMap, GpuError> {
        let res = p.res;
        gpu.check_size(res, res, "shadow map")?;
        let (k, n, q) = (p.k, p.n, p.q);
        let invalid = |e: String| GpuError::Invalid(format!("mdsm: {e}"));
        p.validate().map_err(invalid)?;
        let (kw, qw) = (pcf_width(k).unwrap_or(1), search_width(q).unwrap_or(1));
        let strategy = p.select.index() as u32;
        let lp =
            lightspace::fit(light, &scene.bounds, res).ok_or_else(|| GpuError::Invalid("mdsm does not support point lights".into()))?;
        let region = if n > 1 { qw } else { 1 };
        // the depth pass reads only light_view_proj; the rest mirrors what sm would hold
        let sm_params = SmParams::new(&lp, res, kw as f32, &p.bias);
        let params = MdsmParams {
            light_view_proj: sm_params.light_view_proj,
            texel: sm_params.texel,
            bias: sm_params.bias,
            n,
            region,
            select: strategy,
            region_bias: (p.region_bias && n > 1) as u32,
        };
        let d = &gpu.device;
        let depth = DepthPass::new(gpu, scene, "mdsm", res, &sm_params);
        let nsm = d.create_texture(&wgpu::TextureDescriptor {
            label: Some("mdsm.nsm"),
            size: wgpu::Extent3d { width: res, height: res, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba32Float,
            usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });

        let uniform = gpu.uniform("mdsm.params", &params);
        let storage_out = wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format: wgpu::TextureFormat::Rgba32Float,
            view_dimension: wgpu::TextureViewDimension::D2,
        };
        let select_layout =
            binding::layout(d, "mdsm.select", wgpu::ShaderStages::COMPUTE, &[binding::uniform(), binding::texture_depth(), storage_out]);
        let (depth_view, nsm_view) = (depth.map.create_view(&Default::default()), nsm.create_view(&Default::default()));
        let select_group = binding::group(
            gpu,
            "mdsm.select",
            &select_layout,
            &[uniform.as_entire_binding(), wgpu::BindingResource::TextureView(&depth_view), wgpu::BindingResource::TextureView(&nsm_view)],
        );
        let select_pipeline = gpu.compute_pipeline("mdsm.select", &compose(SELECT_WGSL, false), "main", &[&select_layout]);
        let eval_layout = view_layout(gpu, "mdsm.eval", &[binding::uniform(), binding::texture_float(), binding::storage(false)]);
        let eval = crate::technique::EvalPipelines::new(gpu, "mdsm.eval", &eval_src(), &eval_layout, &[]);
        let counts = gpu.storage("mdsm.counts", res as u64 * res as u64 * 4);
        Ok(MultiDepthMap {
            groups: Default::default(),
            res,
            k,
            n,
            params,
            depth,
            nsm_view: nsm_view.clone(),
            nsm,
            counts,
            uniform,
            select_pipeline,
            select_group,
            eval,
            eval_layout,
        })
    }

    /// The uniform as uploaded (projection, bias, selection settings).
    pub fn params(&self) -> &MdsmParams {
        &self.params
    }

    /// Reads back the base depth map (row-major, `res x res`).
    pub fn read_base(&self, gpu: &Gpu) -> Vec<f32> {
        self.depth.read(gpu)
    }

    /// Reads back the n-SM: per texel Z1 >= ... >= Zn, unused channels repeating Zn.
    pub fn read_selected(&self, gpu: &Gpu) -> Vec<[f32; 4]> {
        bytemuck::pod_collect_to_vec(&gpu.read_texture(&self.nsm, 16))
    }
}

impl Technique for MultiDepthMap {
    fn render(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.depth.render(gpu, f, rec);
        rec.stage("mdsm.select", |enc| {
            gpu.dispatch_2d(enc, "mdsm.select", &self.select_pipeline, &[&self.select_group], self.res, self.res)
        });
        Ok(())
    }

    counted_evaluation!();

    fn report(&mut self, gpu: &Gpu) -> TechniqueReport {
        let texels = (self.res * self.res) as usize;
        let counts: Vec<u32> = gpu.read_buffer_as(&self.counts, texels);
        let depth = self.read_base(gpu);
        // base Depth32Float map + the RGBA32F n-SM
        let bytes = texels as u64 * (4 + 16);
        let mut r = TechniqueReport { shadow_data_bytes: bytes, sampling: Some(sampling_stats(&counts)), ..Default::default() };
        let region = self.params.region;
        r.counters.insert("fetches_per_pixel".into(), self.k as f64);
        r.counters.insert("select_fetches_per_texel".into(), (region * region) as f64);
        r.counters.insert("max_distinct_values".into(), max_distinct(self.k, self.n) as f64);
        r.counters.insert("shadow_map_texels".into(), texels as f64);
        r.images.push(depth_image("base shadow map (depth)", self.res, &depth));
        r.images.push(count_image("view samples per texel", self.res, &counts));
        r
    }
}

impl MultiDepthMap {
    /// The evaluation; with `counting` the lab's analysis variant (view samples per texel).
    fn eval_pass(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder, counting: bool) -> Result<(), GpuError> {
        let nsm_view = &self.nsm_view;
        let group = f.view_group(
            gpu,
            &self.groups,
            "mdsm.eval",
            &self.eval_layout,
            &[self.uniform.as_entire_binding(), wgpu::BindingResource::TextureView(&nsm_view), self.counts.as_entire_binding()],
        );
        self.eval.record(gpu, rec, "mdsm.evaluate", &self.counts, &group, f.gbuffer.width, f.gbuffer.height, counting);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use shadowlab_core::params::{ParamSet, TechniqueSpec};

    fn resolve(spec: &str) -> Result<(), String> {
        crate::registry::resolve(&TechniqueSpec::parse(spec).unwrap(), None).map(|_| ()).map_err(|e| e.to_string())
    }

    #[test]
    fn the_table_keeps_its_keys_and_the_rules_say_why() {
        let keys: Vec<_> = super::MdsmSettings::defs().iter().map(|p| p.key).collect();
        assert_eq!(keys, ["res", "n", "k", "select", "q", "bias", "slope_bias", "max_slope", "normal_offset", "region_bias"]);
        assert!(resolve("mdsm:k=5").unwrap_err().contains("k=5 is not one of [1, 4, 9, 16, 25]"));
        assert!(resolve("mdsm:q=10").unwrap_err().contains("q=10 is not one of"));
        let e = resolve("mdsm:n=1,select=sort").unwrap_err();
        assert!(e.contains("select has no effect: with n=1"), "{e}");
        resolve("mdsm:n=3,select=sort,q=25").unwrap();
        resolve("mdsm:n=1,k=9").unwrap();
    }
}
