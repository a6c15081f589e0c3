//! The CPU halves of techniques, one module per technique folder of shadowlab-gpu
//! (`techniques/<name>/`), so both halves are found by the same name: the pure logic a
//! technique's GPU passes are built around, tested without a GPU.
//!
//! - `csm`: cascade split schemes and slice fits (also the cascades of `lt`)
//! - `cube`: cube faces and their per-face triangle lists (`cube`, `cube-notw`)
//! - `dpsm`: the dual-paraboloid mapping (`dpsm`, `dpsm-notw`)
//! - `filtered`: moments and visibility bounds of VSM, ESM, EVSM and MSM
//! - `iasm`: IASM tile placement, importance and resolution assignment
//! - `lt`: leak tracing's LTT test, temporal mask bits and cascades
//! - `mdsm`: multiple-depth selection and PCF(k,n)
//! - `min_sm`: rotating calipers and the minimal shadow frustum (MSF)
//! - `sdsm`: sample-distribution splits and boxes fitted to the samples (`sdsm`, GPU half in `techniques/sdsm/`, sharing `csm/`'s passes)
//! - `sv`: silhouette edges of closed meshes for shadow volumes
//! - `virtual_sm`: clipmap pages, level choice and page pool of `virtual`
//! - `warp`: RTW and NoTW warping functions

pub mod csm;
pub mod cube;
pub mod dpsm;
pub mod filtered;
pub mod iasm;
pub mod lt;
pub mod mdsm;
pub mod min_sm;
pub mod sdsm;
pub mod sv;
pub mod virtual_sm;
pub mod warp;
