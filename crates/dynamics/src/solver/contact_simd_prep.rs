//! Preparing the four lanes of a wide contact constraint at once (module `contact_simd`):
//! the arithmetic of the scalar `contact::prepare_one` (poses, lever arms, point velocities,
//! warm-start impulses, friction frame) on lane vectors, after gathering each lane's
//! manifold and bodies, then the rows of all lanes ([`WideConstraint::finish_rows`]).
//! Box2D v3's `b2PrepareContactsTask` prepares its SIMD constraints lane by lane; here the
//! per-point work runs on the lanes too, as its solve does.
//!
//! Every lane computes exactly the operations of the scalar routine in the same order
//! (glam's `Quat * Vec3`, `Vec3::normalize`, `Vec3::cross`, `Vec3::dot`; no fused
//! multiply-add), so each lane has the bits of the scalar preparation; lanes without a
//! point or without a constraint are masked to the zeros the scalar route writes there.

use super::build::{keep, lane_index, RowInputs};
use super::run::Isa;
use super::{WideConstraint, WidePoint, LANES, NONE, NO_SLOT, V3, W};
use crate::contact::{ContactManifold, ContactPoint};
use crate::solver::contact::Preparer;
use crate::solver::Softness;
use carom_collision::math::{Quat, Real, Vec3};

/// Lane vector of `f` over the four lanes.
#[inline(always)]
fn lanes(f: impl Fn(usize) -> Real) -> W {
    W::from([f(0), f(1), f(2), f(3)])
}

/// Lane vectors of `f` over the four lanes.
#[inline(always)]
fn lanes3(f: impl Fn(usize) -> Vec3) -> V3 {
    let v = [f(0), f(1), f(2), f(3)];
    V3 {
        x: W::from([v[0].x, v[1].x, v[2].x, v[3].x]),
        y: W::from([v[0].y, v[1].y, v[2].y, v[3].y]),
        z: W::from([v[0].z, v[1].z, v[2].z, v[3].z]),
    }
}

/// `t` in the lanes where `mask` is set, `f` elsewhere.
#[inline(always)]
fn pick3(mask: W, t: V3, f: V3) -> V3 {
    V3 {
        x: mask.select(t.x, f.x),
        y: mask.select(t.y, f.y),
        z: mask.select(t.z, f.z),
    }
}

/// Four quaternions in lanes.
struct WideQuat {
    /// The vector part.
    b: V3,
    /// `w · w − b · b`, as glam computes it inside its rotation.
    ww_b2: W,
    /// `2 w`.
    w2: W,
}

impl WideQuat {
    #[inline(always)]
    fn new(q: [Quat; LANES]) -> WideQuat {
        let b = lanes3(|l| Vec3::new(q[l].x, q[l].y, q[l].z));
        let w = lanes(|l| q[l].w);
        WideQuat {
            b,
            ww_b2: w * w - b.dot(b),
            w2: w * W::splat(2.0),
        }
    }

    /// `q * v` with glam's operations in glam's order (`Quat::mul_vec3`, the same formula
    /// in its SSE2 `f32` and its scalar `f64` version): `v (w² − b·b) + b (2 v·b) +
    /// (b × v) 2w`.
    #[inline(always)]
    fn rotate(&self, v: V3) -> V3 {
        let d2 = v.dot(self.b) * W::splat(2.0);
        v.scale(self.ww_b2)
            .add(self.b.scale(d2))
            .add(self.b.cross(v).scale(self.w2))
    }
}

/// `v · (1 / |v|)`, as glam's `Vec3::normalize` (`v * v.length_recip()`).
#[inline(always)]
fn normalize(v: V3) -> V3 {
    v.scale(W::splat(1.0) / v.dot(v).sqrt())
}

/// `v − n (n · v)`: `v` projected on the plane of `n`, as the scalar friction direction.
#[inline(always)]
fn in_plane(v: V3, n: V3) -> V3 {
    v.sub(n.scale(n.dot(v)))
}

/// The first friction direction of every lane, as `contact_prepare::friction_direction`:
/// the cached direction projected on the tangent plane if long enough, else the sliding
/// direction, else the first vector of `orthonormal_basis(n)` (Duff et al. 2017). The
/// later choices are computed only when a lane needs them.
#[inline(always)]
fn friction_direction(cached: V3, n: V3, relative_velocity: V3) -> V3 {
    let c = in_plane(cached, n);
    let c2 = c.dot(c);
    let use_cached = c2.simd_gt(W::splat(0.25));
    let tc = c.scale(W::splat(1.0) / c2.sqrt());
    if use_cached.all() {
        return tc;
    }
    let vt = in_plane(relative_velocity, n);
    let v2 = vt.dot(vt);
    let use_sliding = v2.simd_gt(W::splat(1e-6));
    let tv = vt.scale(W::splat(1.0) / v2.sqrt());
    // `orthonormal_basis(n).0`, operation by operation.
    let one = W::splat(1.0);
    // `copysign(1, n.z)`: the sign bit of `n.z` on `1.0`.
    let sign = (n.z & W::splat(-0.0)) | one;
    let a = W::splat(-1.0) / (sign + n.z);
    let b = n.x * n.y * a;
    let tb = V3 {
        x: one + sign * n.x * n.x * a,
        y: sign * b,
        z: -sign * n.x,
    };
    pick3(use_cached, tc, pick3(use_sliding, tv, tb))
}

/// A lane's manifold and the slots of its bodies.
#[derive(Clone, Copy)]
struct Lane<'a> {
    m: &'a ContactManifold,
    m_index: usize,
    a: usize,
    b: usize,
}

/// The point of a manifold's array at `k` (stale beyond its length: read, then masked).
#[inline(always)]
fn point(m: &ContactManifold, k: usize) -> &ContactPoint {
    &m.points[k]
}

/// Builds wide constraint `w` from the constraints at positions `ms` of the colour order
/// (`NONE`: a padding lane), all four lanes at once, with the bits of the lane-by-lane
/// build (`build_range` with a [`Preparer`] as its lane source, or the scalar route).
/// `inputs` is scratch for the rows.
#[inline(always)]
fn build_one(
    p: &Preparer<'_>,
    w: &mut WideConstraint,
    ms: &[usize; LANES],
    inputs: &mut RowInputs,
) {
    // Padding lanes compute on the first live lane's inputs and are masked at the end.
    let Some(donor) = ms.iter().position(|&k| k != NONE) else {
        for l in 0..LANES {
            w.set_padding(l, inputs);
        }
        w.len = 0;
        w.finish(inputs);
        return;
    };
    let lane = |l: usize| {
        let k = if ms[l] == NONE { ms[donor] } else { ms[l] };
        let m_index = p.selected[p.order[k]];
        let m = &p.manifolds[m_index];
        Lane {
            m,
            m_index,
            a: m.body_a.index as usize,
            b: m.body_b.index as usize,
        }
    };
    let ls = [lane(0), lane(1), lane(2), lane(3)];
    let live = [0, 1, 2, 3].map(|l| ms[l] != NONE);
    let (bodies, set) = (p.bodies, p.set);
    let ba = ls.map(|x| &bodies[x.a]);
    let bb = ls.map(|x| &bodies[x.b]);
    let lens =
        std::array::from_fn::<usize, LANES, _>(
            |l| if live[l] { ls[l].m.points().len() } else { 0 },
        );
    let len = lens.iter().copied().max().unwrap_or(0);

    // The head's integer fields, lane by lane.
    for l in 0..LANES {
        let (x, on) = (&ls[l], live[l]);
        w.a[l] = if on { lane_index(x.a) } else { NO_SLOT };
        w.b[l] = if on { lane_index(x.b) } else { NO_SLOT };
        w.write_a[l] = on && ba[l].dynamic;
        w.write_b[l] = on && bb[l].dynamic;
        w.manifold[l] = if on { lane_index(x.m_index) } else { NO_SLOT };
        w.lens[l] = lens[l] as u32;
    }
    w.len = len;
    let live_w = W::from(live.map(|on| if on { 1.0 } else { 0.0 })).simd_gt(W::splat(0.0));
    let all_live = live.iter().all(|&on| on);
    let zero = W::splat(0.0);
    let mask = |v: W| if all_live { v } else { live_w.select(v, zero) };

    // Poses: `pose_of` is `(position − q · local_com, q)`.
    let qa = WideQuat::new(ls.map(|x| set.rotation[x.a]));
    let qb = WideQuat::new(ls.map(|x| set.rotation[x.b]));
    let com_a = lanes3(|l| set.position[ls[l].a]);
    let com_b = lanes3(|l| set.position[ls[l].b]);
    let ta = com_a.sub(qa.rotate(lanes3(|l| set.info[ls[l].a].local_com)));
    let tb = com_b.sub(qb.rotate(lanes3(|l| set.info[ls[l].b].local_com)));
    let n = normalize(lanes3(|l| ls[l].m.normal));
    let (va, wa) = (lanes3(|l| ba[l].v), lanes3(|l| ba[l].w));
    let (vb, wb) = (lanes3(|l| bb[l].v), lanes3(|l| bb[l].w));
    let impulse_in = W::splat(p.impulse_in);
    let half = W::splat(0.5);
    let lens_w = W::from(lens.map(|x| x as Real));
    let mut centre = V3::default();
    for k in 0..len {
        let present = lens_w.simd_gt(W::splat(k as Real));
        let all_present = present.all();
        let pt = |l: usize| point(ls[l].m, k);
        let pa = qa.rotate(lanes3(|l| pt(l).local_a)).add(ta);
        let pb = qb.rotate(lanes3(|l| pt(l).local_b)).add(tb);
        let c = pa.add(pb).scale(half);
        let (ra, rb) = (c.sub(com_a), c.sub(com_b));
        let dv = vb.add(wb.cross(rb)).sub(va.add(wa.cross(ra)));
        let sum = centre.add(dv);
        centre = if all_present {
            sum
        } else {
            pick3(present, sum, centre)
        };
        let rv = dv.dot(n);
        let sep = lanes(|l| pt(l).separation);
        let ni = lanes(|l| pt(l).normal_impulse) * impulse_in;
        let ti0 = lanes(|l| pt(l).tangent_impulse[0]) * impulse_in;
        let ti1 = lanes(|l| pt(l).tangent_impulse[1]) * impulse_in;
        let wp: &mut WidePoint = &mut w.points[k];
        let pick = |v: W| {
            if all_present {
                v
            } else {
                present.select(v, zero)
            }
        };
        wp.arm_a = if all_present { ra } else { keep(present, ra) };
        wp.arm_b = if all_present { rb } else { keep(present, rb) };
        wp.separation = pick(sep);
        wp.normal_impulse = pick(ni);
        wp.tangent_impulse = [pick(ti0), pick(ti1)];
        wp.max_normal_impulse = zero;
        w.relative_velocity[k] = pick(rv);
    }
    // `centre_velocity / len` (infinite or NaN in padding lanes, which are masked).
    let mean = V3 {
        x: centre.x / lens_w,
        y: centre.y / lens_w,
        z: centre.z / lens_w,
    };
    let t0 = friction_direction(lanes3(|l| ls[l].m.tangent), n, mean);
    w.normal = if all_live { n } else { keep(live_w, n) };
    w.tangent = if all_live { t0 } else { keep(live_w, t0) };
    w.inv_m_a = mask(lanes(|l| ba[l].inv_m));
    w.inv_m_b = mask(lanes(|l| bb[l].inv_m));
    w.friction = mask(lanes(|l| ls[l].m.friction));
    w.restitution = mask(lanes(|l| ls[l].m.restitution));
    let (soft, static_soft) = p.soft;
    let softness = |l: usize| -> Softness {
        if ba[l].dynamic && bb[l].dynamic {
            soft
        } else {
            static_soft
        }
    };
    w.bias_rate = mask(lanes(|l| softness(l).bias_rate));
    w.mass_scale = mask(lanes(|l| softness(l).mass_scale));
    w.impulse_scale = mask(lanes(|l| softness(l).impulse_scale));
    inputs.set(&ba, &bb);
    w.finish_rows(inputs);
}

/// Builds the wide constraints `ws` whose lanes hold the constraints `ms` (their
/// `WideScratch::members`), four lanes at a time ([`build_one`]), on the best instruction
/// set of the CPU ([`Isa::detect`]): the soft step's prepare blocks (module `soft_stages`).
/// Each wide constraint is written only from its own lanes, so disjoint ranges can be
/// built on different threads with the same bits.
pub(crate) fn build_range_wide(ws: &mut [WideConstraint], ms: &[[usize; LANES]], p: &Preparer<'_>) {
    build_range_wide_on(Isa::detect(), ws, ms, p);
}

/// [`build_range_wide`] on the instruction set `isa`, which the CPU must have
/// ([`Isa::detect`]); a missing one falls back to the baseline.
pub(crate) fn build_range_wide_on(
    isa: Isa,
    ws: &mut [WideConstraint],
    ms: &[[usize; LANES]],
    p: &Preparer<'_>,
) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::is_x86_feature_detected as has;
        if isa == Isa::Avx512 && has!("avx512f") && has!("avx512vl") {
            // SAFETY: the CPU has the features.
            return unsafe { x86::range_avx512(ws, ms, p) };
        }
        if isa != Isa::Base && has!("avx") {
            // SAFETY: the CPU has the feature.
            return unsafe { x86::range_avx(ws, ms, p) };
        }
    }
    let _ = isa;
    range_base(ws, ms, p);
}

/// The loop of [`build_range_wide`] on the baseline instruction set.
#[inline(never)]
fn range_base(ws: &mut [WideConstraint], ms: &[[usize; LANES]], p: &Preparer<'_>) {
    let mut inputs = RowInputs::default();
    for (w, m) in ws.iter_mut().zip(ms) {
        build_one(p, w, m, &mut inputs);
    }
}

/// [`range_base`] compiled for AVX and for AVX-512 (see [`Isa`]): the same lane
/// operations, in three-operand encodings.
#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::{build_one, Preparer, RowInputs, WideConstraint, LANES};

    macro_rules! compiled_for {
        ($features:literal, $range:ident) => {
            /// The build loop compiled for the instruction set named by its suffix.
            ///
            /// # Safety
            /// The CPU has these features.
            #[inline(never)]
            #[target_feature(enable = $features)]
            pub(super) unsafe fn $range(
                ws: &mut [WideConstraint],
                ms: &[[usize; LANES]],
                p: &Preparer<'_>,
            ) {
                let mut inputs = RowInputs::default();
                for (w, m) in ws.iter_mut().zip(ms) {
                    build_one(p, w, m, &mut inputs);
                }
            }
        };
    }

    compiled_for!("avx", range_avx);
    compiled_for!("avx512f,avx512vl", range_avx512);
}
