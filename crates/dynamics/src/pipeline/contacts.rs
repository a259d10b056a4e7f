//! The adapter between the narrowphase's persistent manifolds and the solver's contacts.
//!
//! `gather` turns every non-empty, non-sensor narrowphase manifold with a dynamic body into
//! a [`ContactManifold`] (normal A→B, see the module docs of [`crate::pipeline`]), carrying
//! the accumulated impulses in; `write_back` stores the solver's impulses into the same
//! narrowphase points afterwards. Pairs whose joint disables collisions never get points:
//! the world excludes them from contact generation ([`World::create_joint`]).
//!
//! The buffer is overwritten in place, field by field, from step to step (no manifold is
//! built and then moved), and entry `k` keeps the index of its narrowphase pair in
//! `sources[k]`, so the write-back jumps from pair to pair (`Iterator::nth` on the pair
//! slice is a pointer step) instead of walking and filtering every pair. While copying, the
//! gather sums every value it hands on (finite when all are, short of an overflow beyond
//! 10³⁸: the test of `DynamicsWorld`'s `plausible` up to a needless validation), so the
//! dynamics step need not check each manifold again.
//!
//! The frames need no per-manifold sign: `orthonormal_basis(n)` returns `(t₁, t₂)` with
//! `t₁ × t₂ = n`, so for the solver's normal `n = −n_B` its second tangent `n × t₁` is
//! `−t₂`, and the second friction impulse changes sign between the two (exact in floating
//! point). `frame_sign_is_minus_one` checks the identity.

use super::World;
use crate::body::{mix_friction, mix_restitution, BodyType};
use crate::body_set::{BodyHandle, BodyInfo, BodySet};
use crate::contact::ContactManifold;
use carom_collision::math::{orthonormal_basis, Real, Vec3};
use carom_collision::narrowphase::PairContact;
use carom_collision::world::ObjectHandle;

impl World {
    /// Fills `self.contacts` from the narrowphase (see the module docs). Returns true when
    /// every manifold is certainly valid for the solver (the checks of
    /// [`crate::DynamicsWorld::step`] hold), false when one may not be (the step then
    /// validates them all and names the bad value). Only manifolds with an awake dynamic
    /// body are handed on; with `resting`, the touching pairs left out for that reason go to
    /// `self.resting_pairs` for the islands (cleared otherwise; see [`push_resting`]).
    #[inline(never)] // its own entry in profiles
    pub(super) fn gather(&mut self, resting: bool) -> bool {
        let World {
            dynamics,
            collision,
            body_of,
            contacts,
            sources,
            chunk_counts,
            resting_pairs,
            ..
        } = self;
        let pairs = collision.narrowphase().pair_slice();
        resting_pairs.clear();
        gather_pairs_chunked(
            dynamics.bodies(),
            body_of,
            pairs,
            (contacts, sources),
            resting.then_some(resting_pairs),
            chunk_counts,
            GATHER_CHUNK,
        )
    }

    /// Stores the solver's impulses into the narrowphase points the contacts came from.
    #[inline(never)] // its own entry in profiles
    pub(super) fn write_back(&mut self) {
        if self.contacts.is_empty() {
            // Nothing to store; not borrowing the pairs mutably keeps a settled
            // narrowphase settled (an idle world's quiet steps).
            return;
        }
        let (contacts, sources) = (&self.contacts, &self.sources);
        let pairs = self.collision.narrowphase_mut().pair_slice_mut();
        write_back_range(contacts, sources, pairs, 0, GATHER_CHUNK);
    }

    /// Number of contact points handed to the solver at the last step.
    pub(super) fn contact_point_count(&self) -> usize {
        self.contacts.iter().map(|m| m.points().len()).sum()
    }
}

/// Pairs per chunk of the parallel gather, and manifolds per task of the parallel write-back
/// (a chunk of pairs, ~100 kB, stays in a core's L2 cache between the gather's two passes).
pub(super) const GATHER_CHUNK: usize = 512;

/// Stores `contacts`' impulses into the narrowphase points they came from: `sources[k]` is
/// the index in `pairs` (which starts at pair `base`) of `contacts[k]`'s pair, ascending. In
/// halves run by `rayon::join` down to `chunk` manifolds (the `parallel` feature, more than
/// one thread): the sources split the pairs into disjoint ranges, so the writes do not
/// depend on the thread count.
pub(super) fn write_back_range(
    contacts: &[ContactManifold],
    sources: &[u32],
    pairs: &mut [PairContact<ObjectHandle>],
    base: usize,
    chunk: usize,
) {
    #[cfg(feature = "parallel")]
    if contacts.len() > chunk.max(1) && rayon::current_num_threads() > 1 {
        let mid = contacts.len() / 2;
        let split = (sources[mid] as usize - base).min(pairs.len());
        let (c0, c1) = contacts.split_at(mid);
        let (s0, s1) = sources.split_at(mid);
        let (p0, p1) = pairs.split_at_mut(split);
        rayon::join(
            || write_back_range(c0, s0, p0, base, chunk),
            || write_back_range(c1, s1, p1, base + split, chunk),
        );
        return;
    }
    let _ = chunk;
    for (m, &index) in contacts.iter().zip(sources) {
        let Some(pc) = pairs.get_mut(index as usize - base) else {
            break;
        };
        for (p, q) in pc.manifold.points.iter_mut().zip(m.points()) {
            p.normal_impulse = q.normal_impulse;
            p.tangent_impulse = [q.tangent_impulse[0], -q.tangent_impulse[1]];
        }
    }
}

/// A body is awake for the solver: dynamic and not sleeping.
#[inline(always)]
fn awake(i: &BodyInfo) -> bool {
    i.body_type == BodyType::Dynamic && !i.sleeping
}

/// Appends the touching pair `pc` of bodies `ba`, `bb` to `out` when neither is awake and
/// its manifold would pass the gather's normal check.
#[inline(always)]
fn push_resting(
    out: &mut Vec<(usize, usize)>,
    pc: &PairContact<ObjectHandle>,
    (ba, bb): (BodyHandle, BodyHandle),
    (info_a, info_b): (&BodyInfo, &BodyInfo),
) {
    if !(awake(info_a) || awake(info_b)) && unit_deepest_normal(&pc.manifold.points) {
        out.push((ba.index as usize, bb.index as usize));
    }
}

/// True when the deepest point's normal (the first of equally deep ones) is finite and
/// unit, as [`fill_manifold`] requires of a manifold it hands on.
fn unit_deepest_normal(points: &[carom_collision::narrowphase::ContactPoint]) -> bool {
    let Some(first) = points.first() else {
        return false;
    };
    let deepest = points
        .iter()
        .fold(first, |d, p| if p.distance < d.distance { p } else { d });
    let n = deepest.normal;
    n.is_finite() && (n.length_squared() - 1.0).abs() <= 1e-3
}

/// The bodies of a pair the gather looks at: a non-empty, non-sensor manifold between two
/// distinct live bodies, one of them dynamic.
#[inline(always)]
fn touching_bodies<'s>(
    set: &'s BodySet,
    body_of: &[Option<BodyHandle>],
    pc: &PairContact<ObjectHandle>,
) -> Option<(BodyHandle, BodyHandle, &'s BodyInfo, &'s BodyInfo)> {
    if pc.manifold.points.is_empty() || pc.sensor {
        return None;
    }
    let body = |o: ObjectHandle| body_of.get(o.index as usize).copied().flatten();
    let (ba, bb) = (body(pc.a)?, body(pc.b)?);
    // One at a time: a tuple of the two `Result`s (with their error payloads) was built on
    // the stack for every manifold (~30 instructions of copies).
    let ia = set.slot(ba).ok()?;
    let ib = set.slot(bb).ok()?;
    let (info_a, info_b) = (&set.info[ia], &set.info[ib]);
    let dynamic = |t: BodyType| t == BodyType::Dynamic;
    if !(dynamic(info_a.body_type) || dynamic(info_b.body_type)) || ba == bb {
        return None;
    }
    Some((ba, bb, info_a, info_b))
}

/// [`gather_pairs`] over the slice `pairs`, in chunks of `chunk` pairs run in parallel (the
/// `parallel` feature, more than one thread, at least two chunks): a first pass counts each
/// chunk's manifolds (and, with `resting`, its resting edges) from the pairs' headers
/// ([`touching_bodies`]) into `counts`, a second fills every chunk's own range of
/// `contacts`, `sources` and the resting edges (halves run by `rayon::join`). The manifolds
/// and edges are those of the serial pass, bit for bit and in pair order, whatever the
/// thread count. A manifold whose normal the serial pass would drop (not finite or not
/// unit: a range would keep a hole) sends the whole gather to the serial pass.
/// With `resting`, the touching pairs left out because neither body is awake are appended
/// to it (in pair order). (They were found by a serial pass over every pair after the
/// parallel ones: 0.18 ms a step of "3000 fall" with sleeping on.)
pub(super) fn gather_pairs_chunked(
    set: &BodySet,
    body_of: &[Option<BodyHandle>],
    pairs: &[PairContact<ObjectHandle>],
    (contacts, sources): (&mut Vec<ContactManifold>, &mut Vec<u32>),
    mut resting: Option<&mut Vec<(usize, usize)>>,
    counts: &mut Vec<(u32, u32)>,
    chunk: usize,
) -> bool {
    let start = resting.as_deref().map_or(0, Vec::len);
    let out = (&mut *contacts, &mut *sources);
    match gather_parallel(
        set,
        body_of,
        pairs,
        out,
        resting.as_deref_mut(),
        counts,
        chunk,
    ) {
        Some(checked) => checked,
        None => {
            if let Some(r) = resting.as_deref_mut() {
                r.truncate(start);
            }
            gather_pairs(set, body_of, pairs.iter(), (contacts, sources), resting)
        }
    }
}

/// The parallel passes of [`gather_pairs_chunked`], or `None` when they did not run (one
/// thread, fewer than two chunks, no `parallel` feature) or a manifold was dropped for its
/// normal (`resting` may then hold edges past its old length).
pub(super) fn gather_parallel(
    set: &BodySet,
    body_of: &[Option<BodyHandle>],
    pairs: &[PairContact<ObjectHandle>],
    (contacts, sources): (&mut Vec<ContactManifold>, &mut Vec<u32>),
    resting: Option<&mut Vec<(usize, usize)>>,
    counts: &mut Vec<(u32, u32)>,
    chunk: usize,
) -> Option<bool> {
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        let chunk = chunk.max(1);
        if rayon::current_num_threads() > 1 && pairs.len() >= 2 * chunk {
            let with_resting = resting.is_some();
            pairs
                .par_chunks(chunk)
                .map(|c| {
                    let (mut handed, mut rest) = (0u32, 0u32);
                    for pc in c {
                        match sort_pair(set, body_of, pc, with_resting) {
                            Some(Sorted::Handed(..)) => handed += 1,
                            Some(Sorted::Resting(..)) => rest += 1,
                            None => {}
                        }
                    }
                    (handed, rest)
                })
                .collect_into_vec(counts);
            // Exclusive prefix sums: each chunk's first manifold and first edge.
            let (mut total, mut total_rest) = (0u32, 0u32);
            for c in counts.iter_mut() {
                let (h, r) = *c;
                *c = (total, total_rest);
                (total, total_rest) = (total + h, total_rest + r);
            }
            let placeholder = BodyHandle {
                index: 0,
                generation: 0,
            };
            contacts.resize(
                total as usize,
                ContactManifold::new(placeholder, placeholder, Vec3::Z),
            );
            sources.resize(total as usize, 0);
            let mut no_edges = Vec::new();
            let rest: &mut [(usize, usize)] = match resting {
                Some(r) => {
                    let start = r.len();
                    r.resize(start + total_rest as usize, (0, 0));
                    &mut r[start..]
                }
                None => &mut no_edges,
            };
            let (sum, ok) = fill_chunks(
                (set, body_of, with_resting),
                pairs,
                (contacts, sources, rest),
                (counts, 0),
                chunk,
            )?;
            return Some(sum.is_finite() && ok);
        }
    }
    let _ = (
        set, body_of, pairs, contacts, sources, resting, counts, chunk,
    );
    None
}

/// What the gather does with a pair.
#[cfg(feature = "parallel")]
enum Sorted<'s> {
    /// A manifold handed on to the solver (an awake body).
    Handed(BodyHandle, BodyHandle, &'s BodyInfo, &'s BodyInfo),
    /// A resting edge for the islands (no awake body; only looked for `with_resting`).
    Resting(usize, usize),
}

/// The gather's decision for `pc`: handed on when a body is awake (a sleeping body is not
/// moved, so a pile that sleeps hands nothing on), else (with `with_resting`) the resting
/// edge [`push_resting`] would append, so a sleeping pile wakes whole, else nothing. Reads
/// the pair's header, and its points only for a resting edge's normal check.
#[cfg(feature = "parallel")]
#[inline(always)]
fn sort_pair<'s>(
    set: &'s BodySet,
    body_of: &[Option<BodyHandle>],
    pc: &PairContact<ObjectHandle>,
    with_resting: bool,
) -> Option<Sorted<'s>> {
    let (ba, bb, info_a, info_b) = touching_bodies(set, body_of, pc)?;
    if awake(info_a) || awake(info_b) {
        return Some(Sorted::Handed(ba, bb, info_a, info_b));
    }
    (with_resting && unit_deepest_normal(&pc.manifold.points))
        .then_some(Sorted::Resting(ba.index as usize, bb.index as usize))
}

/// The slices [`fill_chunks`] writes: manifolds, their sources and resting edges.
#[cfg(feature = "parallel")]
type FillOut<'a> = (
    &'a mut [ContactManifold],
    &'a mut [u32],
    &'a mut [(usize, usize)],
);

/// The second pass of [`gather_pairs_chunked`] over the chunks whose first manifolds and
/// edges are `firsts.0` (the first chunk is chunk `firsts.1` of the whole slice): `out`
/// holds exactly their manifolds, sources and resting edges. Returns the sum and the range
/// test of the values handed on, or `None` when a manifold was dropped for its normal.
#[cfg(feature = "parallel")]
fn fill_chunks(
    ctx: (&BodySet, &[Option<BodyHandle>], bool),
    pairs: &[PairContact<ObjectHandle>],
    out: FillOut<'_>,
    firsts: (&[(u32, u32)], usize),
    chunk: usize,
) -> Option<(Real, bool)> {
    let (contacts, sources, rest) = out;
    let (firsts, first_chunk) = firsts;
    if firsts.len() > 1 {
        let mid = firsts.len() / 2;
        let split = (firsts[mid].0 - firsts[0].0) as usize;
        let split_rest = (firsts[mid].1 - firsts[0].1) as usize;
        let (c0, c1) = contacts.split_at_mut(split);
        let (s0, s1) = sources.split_at_mut(split);
        let (r0, r1) = rest.split_at_mut(split_rest);
        let (f0, f1) = firsts.split_at(mid);
        let (p0, p1) = pairs.split_at((mid * chunk).min(pairs.len()));
        let (a, b) = rayon::join(
            || fill_chunks(ctx, p0, (c0, s0, r0), (f0, first_chunk), chunk),
            || fill_chunks(ctx, p1, (c1, s1, r1), (f1, first_chunk + mid), chunk),
        );
        let ((sa, oa), (sb, ob)) = (a?, b?);
        return Some((sa + sb, oa && ob));
    }
    let (set, body_of, with_resting) = ctx;
    let base = first_chunk * chunk;
    let (mut k, mut r) = (0, 0);
    let (mut sum, mut ok): (Real, bool) = (0.0, true);
    for (index, pc) in pairs.iter().enumerate() {
        match sort_pair(set, body_of, pc, with_resting) {
            Some(Sorted::Handed(ba, bb, info_a, info_b)) => {
                let m = contacts.get_mut(k)?;
                let (values, ranges_ok) = fill_manifold(m, pc, (ba, bb), (info_a, info_b))?;
                sum += values;
                ok &= ranges_ok;
                sources[k] = (base + index) as u32;
                k += 1;
            }
            Some(Sorted::Resting(a, b)) => {
                *rest.get_mut(r)? = (a, b);
                r += 1;
            }
            None => {}
        }
    }
    (k == contacts.len() && r == rest.len()).then_some((sum, ok))
}

/// Fills solver manifold `m` from narrowphase pair `pc` between bodies `ba`, `bb` (see
/// [`gather_pairs`]): the points, the deepest point's normal (negated: A→B), the tangent and
/// the mixed friction and restitution. Returns the sum of the values handed on and whether
/// friction and restitution are in range, or `None` when the normal is not finite and unit
/// (the manifold is then not handed on; its copied points stay unused).
#[inline(always)]
fn fill_manifold(
    m: &mut ContactManifold,
    pc: &PairContact<ObjectHandle>,
    (ba, bb): (BodyHandle, BodyHandle),
    (info_a, info_b): (&BodyInfo, &BodyInfo),
) -> Option<(Real, bool)> {
    let points = &pc.manifold.points[..];
    let first = points.first()?;
    // The deepest point (the first of equally deep ones), found while copying: the
    // comparisons are those of a separate scan (`first` against itself is false).
    let mut deepest = first;
    let mut len = 0;
    // This manifold's sum, counted only if the manifold is handed on.
    let mut values: Real = 0.0;
    for (q, p) in m.points.iter_mut().zip(points) {
        if p.distance < deepest.distance {
            deepest = p;
        }
        q.local_a = p.local_a;
        q.local_b = p.local_b;
        q.separation = p.distance;
        q.feature_id = p.feature;
        q.normal_impulse = p.normal_impulse;
        q.tangent_impulse = [p.tangent_impulse[0], -p.tangent_impulse[1]];
        values += (p.local_a + p.local_b).element_sum()
            + ((p.distance + p.normal_impulse) + (p.tangent_impulse[0] + p.tangent_impulse[1]));
        len += 1;
    }
    // More points than a solver manifold holds (not from the narrowphase, which keeps
    // four): the deepest of all of them still gives the normal.
    for p in points.get(len..).unwrap_or_default() {
        if p.distance < deepest.distance {
            deepest = p;
        }
    }
    let n_b = deepest.normal;
    if !n_b.is_finite() || (n_b.length_squared() - 1.0).abs() > 1e-3 {
        return None;
    }
    let (t1, _) = orthonormal_basis(n_b);
    m.len = len;
    m.body_a = ba;
    m.body_b = bb;
    m.normal = -n_b;
    m.tangent = t1;
    m.friction = mix_friction(info_a.friction, info_b.friction);
    m.restitution = mix_restitution(info_a.restitution, info_b.restitution);
    let ranges_ok = m.friction >= 0.0 && (0.0..=1.0).contains(&m.restitution);
    Some((values + m.friction, ranges_ok))
}

/// [`World::gather`] over `pairs` (the narrowphase's, in pair order): fills `contacts` and
/// `sources` in place and returns whether every value handed on is certainly valid.
///
/// One pass per manifold: the points are copied while the deepest one is found (its normal
/// is the manifold's), and the values are summed rather than multiplied by zero and summed:
/// a sum of finite values is finite unless it overflows (beyond 10³⁸, no scene's values), and
/// any infinite or NaN value makes it infinite or NaN, so `sum.is_finite()` is true only when
/// all are finite. A false "not certain" costs the step a validation, never other bits.
/// The manifolds are the same bits as `gather_reference`'s (the previous routine, kept as
/// the test oracle in `contacts_tests.rs`).
pub(super) fn gather_pairs<'p>(
    set: &BodySet,
    body_of: &[Option<BodyHandle>],
    pairs: impl Iterator<Item = &'p PairContact<ObjectHandle>>,
    (contacts, sources): (&mut Vec<ContactManifold>, &mut Vec<u32>),
    mut resting: Option<&mut Vec<(usize, usize)>>,
) -> bool {
    let mut k = 0;
    let mut sum: Real = 0.0;
    let mut ranges_ok = true;
    for (index, pc) in pairs.enumerate() {
        let Some((ba, bb, info_a, info_b)) = touching_bodies(set, body_of, pc) else {
            continue;
        };
        if !(awake(info_a) || awake(info_b)) {
            if let Some(out) = resting.as_deref_mut() {
                push_resting(out, pc, (ba, bb), (info_a, info_b));
            }
            continue;
        }
        if k == contacts.len() {
            contacts.push(ContactManifold::new(ba, bb, Vec3::Z));
            sources.push(0);
        }
        // A manifold dropped for its normal leaves entry `k` to be refilled or truncated.
        let Some((values, ok)) = fill_manifold(&mut contacts[k], pc, (ba, bb), (info_a, info_b))
        else {
            continue;
        };
        sum += values;
        ranges_ok &= ok;
        sources[k] = index as u32;
        k += 1;
    }
    contacts.truncate(k);
    sources.truncate(k);
    sum.is_finite() && ranges_ok
}

#[cfg(test)]
mod tests {
    use carom_collision::math::{orthonormal_basis, Real, Vec3};

    /// The solver's second tangent `(−n) × t₁` is `−t₂` for the narrowphase's basis: the
    /// adapter maps the second friction impulse by a sign change. Normals on and near the
    /// poles (the basis' branch), along the axes, and spread over the sphere.
    #[test]
    fn frame_sign_is_minus_one() {
        let mut normals = vec![
            Vec3::X,
            -Vec3::X,
            Vec3::Y,
            -Vec3::Y,
            Vec3::Z,
            -Vec3::Z,
            Vec3::new(1e-7, 0.0, -1.0).normalize(),
            Vec3::new(0.0, 1e-7, 1.0).normalize(),
            Vec3::new(0.0, 0.0, -0.0) + Vec3::new(0.0, 1.0, -1e-30).normalize(),
        ];
        for i in 0..2000 {
            let u = (i as Real + 0.5) / 2000.0;
            let z = 1.0 - 2.0 * u;
            let phi = i as Real * 2.399_963;
            let r = (1.0 - z * z).max(0.0).sqrt();
            normals.push(Vec3::new(r * phi.cos(), r * phi.sin(), z).normalize());
        }
        for n_b in normals {
            let (t1, t2) = orthonormal_basis(n_b);
            let second = (-n_b).cross(t1);
            assert!(
                t2.dot(second) < -0.99 && (second + t2).length() < 1e-4,
                "{n_b}: {t1} {t2} {second}"
            );
            // What the old adapter computed per manifold.
            assert_eq!(t2.dot(second).signum(), -1.0);
        }
    }
}
