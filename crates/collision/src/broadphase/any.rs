//! [`AnyBroadPhase`]: every method behind one enum (static dispatch, no `dyn`), chosen by
//! [`Method`]; and [`overlapping_pairs`], the one-call form for bindings.

use super::{BroadPhase, BruteForce, Filter, HashGrid, HierarchicalGrid, InsertStrategy};
use super::{PairChanges, ProxyHandle, SortSweep, SweepAndPrune, TreeBroadPhase, UserFilter};
use crate::error::{CaromError, Result};
use crate::math::{Aabb, Real, Vec3};
use std::str::FromStr;

/// The broadphase methods.
///
/// The default is [`Method::Tree`]: its cost follows the proxies whose fat boxes moved and
/// the candidate pairs, not N, and on every benchmark scene (`carom-bench scenes`, the
/// pipeline's boxes replayed by `examples/broadphase_replay.rs`) it took 1.6x (3000 falling
/// boxes) to 5x (1000 resting boxes) fewer instructions per step than the hierarchical
/// grid, and fewer than every other method. Prefer [`Method::HGrid`] or [`Method::Grid`]
/// when nearly every object jumps far at every update (the CDTestFramework scene of
/// `carom-bench broadphase`, where the grids win from 8k boxes up) or for one-shot batches.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Method {
    /// Two dynamic AABB trees with SAH insertion ([`TreeBroadPhase`]), the default.
    #[default]
    Tree,
    /// Two dynamic AABB trees with Bullet's Manhattan-distance insertion.
    TreeManhattan,
    /// Incremental 3-axis sweep-and-prune ([`SweepAndPrune`]).
    Sap,
    /// 1-axis sort-and-sweep from scratch, parallel ([`SortSweep`]).
    SortSweep,
    /// Uniform hashed grid ([`HashGrid`]).
    Grid,
    /// Hierarchical hashed grid ([`HierarchicalGrid`]).
    HGrid,
    /// All pairs ([`BruteForce`]), the reference.
    BruteForce,
}

impl Method {
    /// Every method, in a fixed order.
    pub const ALL: [Method; 7] = [
        Method::Tree,
        Method::TreeManhattan,
        Method::Sap,
        Method::SortSweep,
        Method::Grid,
        Method::HGrid,
        Method::BruteForce,
    ];

    /// The method's name as accepted by [`Method::from_str`].
    pub fn name(self) -> &'static str {
        match self {
            Method::Tree => "tree",
            Method::TreeManhattan => "tree_manhattan",
            Method::Sap => "sap",
            Method::SortSweep => "sort_sweep",
            Method::Grid => "grid",
            Method::HGrid => "hgrid",
            Method::BruteForce => "brute_force",
        }
    }
}

impl FromStr for Method {
    type Err = CaromError;

    fn from_str(s: &str) -> Result<Self> {
        Method::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| {
                CaromError::invalid(
                    "method",
                    s,
                    "expected tree, tree_manhattan, sap, sort_sweep, grid, hgrid or brute_force",
                )
            })
    }
}

/// Any broadphase, dispatched by `match`.
#[derive(Debug, Clone)]
#[allow(clippy::large_enum_variant)]
pub enum AnyBroadPhase {
    /// Two-tree broadphase (either insertion strategy).
    Tree(TreeBroadPhase),
    /// Incremental sweep-and-prune.
    Sap(SweepAndPrune),
    /// Sort-and-sweep.
    SortSweep(SortSweep),
    /// Uniform grid.
    Grid(HashGrid),
    /// Hierarchical grid.
    HGrid(HierarchicalGrid),
    /// Brute force.
    BruteForce(BruteForce),
}

impl Default for AnyBroadPhase {
    fn default() -> Self {
        AnyBroadPhase::new(Method::default())
    }
}

impl AnyBroadPhase {
    /// A new, empty broadphase of the given method with default settings.
    pub fn new(method: Method) -> Self {
        match method {
            Method::Tree => AnyBroadPhase::Tree(TreeBroadPhase::new(
                InsertStrategy::SurfaceArea,
                TreeBroadPhase::DEFAULT_MARGIN,
            )),
            Method::TreeManhattan => AnyBroadPhase::Tree(TreeBroadPhase::new(
                InsertStrategy::Manhattan,
                TreeBroadPhase::DEFAULT_MARGIN,
            )),
            Method::Sap => AnyBroadPhase::Sap(SweepAndPrune::new()),
            Method::SortSweep => AnyBroadPhase::SortSweep(SortSweep::new()),
            Method::Grid => AnyBroadPhase::Grid(HashGrid::new(None)),
            Method::HGrid => AnyBroadPhase::HGrid(HierarchicalGrid::new()),
            Method::BruteForce => AnyBroadPhase::BruteForce(BruteForce::new()),
        }
    }

    /// [`BroadPhase::update_proxy`] for a caller that has checked that `proxy` is live, that
    /// `aabb` is finite with `min <= max` and that `displacement` is finite: the two-tree
    /// method skips its checks, the others take the checked path.
    #[inline]
    pub(crate) fn update_proxy_checked(
        &mut self,
        proxy: ProxyHandle,
        aabb: &Aabb,
        displacement: Vec3,
    ) -> Result<()> {
        match self {
            AnyBroadPhase::Tree(b) => {
                b.update_slot(proxy.index as usize, aabb, displacement);
                Ok(())
            }
            b => b.inner_mut().update_proxy(proxy, *aabb, displacement),
        }
    }

    fn inner(&self) -> &dyn BroadPhase {
        match self {
            AnyBroadPhase::Tree(b) => b,
            AnyBroadPhase::Sap(b) => b,
            AnyBroadPhase::SortSweep(b) => b,
            AnyBroadPhase::Grid(b) => b,
            AnyBroadPhase::HGrid(b) => b,
            AnyBroadPhase::BruteForce(b) => b,
        }
    }

    fn inner_mut(&mut self) -> &mut dyn BroadPhase {
        match self {
            AnyBroadPhase::Tree(b) => b,
            AnyBroadPhase::Sap(b) => b,
            AnyBroadPhase::SortSweep(b) => b,
            AnyBroadPhase::Grid(b) => b,
            AnyBroadPhase::HGrid(b) => b,
            AnyBroadPhase::BruteForce(b) => b,
        }
    }
}

impl BroadPhase for AnyBroadPhase {
    fn name(&self) -> &'static str {
        self.inner().name()
    }
    fn create_proxy(&mut self, aabb: Aabb, filter: Filter) -> Result<ProxyHandle> {
        self.inner_mut().create_proxy(aabb, filter)
    }
    fn update_proxy(&mut self, proxy: ProxyHandle, aabb: Aabb, displacement: Vec3) -> Result<()> {
        self.inner_mut().update_proxy(proxy, aabb, displacement)
    }
    fn remove_proxy(&mut self, proxy: ProxyHandle) -> Result<()> {
        self.inner_mut().remove_proxy(proxy)
    }
    fn set_filter(&mut self, proxy: ProxyHandle, filter: Filter) -> Result<()> {
        self.inner_mut().set_filter(proxy, filter)
    }
    fn set_resting(&mut self, proxy: ProxyHandle, resting: bool) -> Result<()> {
        self.inner_mut().set_resting(proxy, resting)
    }
    fn set_user_filter(&mut self, filter: Option<UserFilter>) {
        self.inner_mut().set_user_filter(filter)
    }
    fn update_pairs(&mut self) -> &PairChanges {
        self.inner_mut().update_pairs()
    }
    fn pairs(&self) -> Vec<(ProxyHandle, ProxyHandle)> {
        self.inner().pairs()
    }
    fn pair_count(&self) -> usize {
        self.inner().pair_count()
    }
    fn aabb(&self, proxy: ProxyHandle) -> Result<Aabb> {
        self.inner().aabb(proxy)
    }
    fn len(&self) -> usize {
        self.inner().len()
    }
}

/// All pairs `(i, j)`, `i < j`, of boxes `[mins[i], maxs[i]]` that overlap (touching
/// included), sorted, found with `method`. Invalid boxes (NaN, min > max) or arrays of
/// different lengths are errors naming the index.
pub fn overlapping_pairs(
    mins: &[[Real; 3]],
    maxs: &[[Real; 3]],
    method: Method,
) -> Result<Vec<(u32, u32)>> {
    if mins.len() != maxs.len() {
        return Err(CaromError::invalid(
            "maxs.len()",
            maxs.len(),
            format!("must equal mins.len() = {}", mins.len()),
        ));
    }
    let mut bp = AnyBroadPhase::new(method);
    for (i, (lo, hi)) in mins.iter().zip(maxs).enumerate() {
        let aabb = Aabb::new(Vec3::from_array(*lo), Vec3::from_array(*hi));
        bp.create_proxy(aabb, Filter::default())
            .map_err(|e| CaromError::invalid(format!("box[{i}]"), aabb, e.to_string()))?;
    }
    bp.update_pairs();
    Ok(bp
        .pairs()
        .into_iter()
        .map(|(a, b)| (a.index, b.index))
        .collect())
}
