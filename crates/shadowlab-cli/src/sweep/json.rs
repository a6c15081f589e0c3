//! `sweep.json`, typed: the plan, one row per point run, the aggregates over setups and the
//! recommendation. Fields are described in docs/sweep.md.

use serde::{Deserialize, Serialize};

use super::choose::{Aggregate, Budget, Recommendation};
use super::record::{PlanEntry, Row, SetupInfo, Shard};

/// sweep.json.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sweep {
    pub schema_version: u32,
    /// The adapter(s) of the rows (joined with `; ` when merged shards differ).
    pub adapter: String,
    /// A CPU adapter (lavapipe/llvmpipe): its times are not a GPU's.
    pub software_adapter: bool,
    /// Which clock `total_ms` is.
    pub timer: String,
    /// Which clock `stages_ms` are.
    pub stages_timer: String,
    pub frames: usize,
    pub repeat: usize,
    pub light: usize,
    /// `--time`, or null: each setup's own `time`
    pub time: Option<f32>,
    pub setups: Vec<SetupInfo>,
    /// This output's share of the plan; null for a whole sweep (or a merge).
    pub shard: Option<Shard>,
    /// Every point of the sweep, over all shards.
    pub plan: Vec<PlanEntry>,
    /// Points computed by this invocation.
    pub points_computed: usize,
    /// Points read from `points/` (finished earlier, or by the merged shards).
    pub points_cached: usize,
    /// Views (setup x frame) whose G-buffer and reference this invocation computed.
    pub views_computed: usize,
    /// Shard directories merged into this one (`sweep merge`); empty otherwise.
    pub merged_from: Vec<String>,
    /// One row per point of this output, in plan order.
    pub rows: Vec<Row>,
    /// Per label, over the setups it ran on.
    pub aggregates: Vec<Aggregate>,
    pub budget: Budget,
    /// With a budget: the best spec within it.
    pub recommendation: Option<Recommendation>,
}

impl Sweep {
    /// Pretty JSON with keys sorted at every level.
    pub fn to_json(&self) -> serde_json::Result<String> {
        serde_json::to_string_pretty(&serde_json::to_value(self)?)
    }
}
