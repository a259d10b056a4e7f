//! Running the wide passes (module `contact_simd`): the body gather and scatter around one
//! wide constraint (Box2D v3's `b2GatherBodies`, `b2ScatterBodies`), the loop over a block
//! of a colour, and the choice of instruction set for it.

use super::{WideBody, WideConstraint, LANES, NO_SLOT, V3, W};
use crate::solver::SolverBody;
use carom_collision::math::Real;
use std::ops::Range;

/// A pass over one wide constraint whose bodies have been gathered into lanes.
pub(crate) trait WideKernel {
    /// Runs the pass on `c` and its bodies' lanes `a`, `b`. Implementations should be
    /// `#[inline(always)]`: [`kernel`] and [`kernel_avx512`] are the call boundary, and the
    /// pass must be compiled into each of them to run on its instruction set.
    fn run(&self, c: &mut WideConstraint, a: &mut WideBody, b: &mut WideBody);
}

/// The warm start ([`super::warm_start`]).
pub(crate) struct WarmStart;

impl WideKernel for WarmStart {
    #[inline(always)]
    fn run(&self, c: &mut WideConstraint, a: &mut WideBody, b: &mut WideBody) {
        super::warm_start(c, a, b)
    }
}

/// The soft solve or relax pass ([`super::solve_soft`] with these arguments).
pub(crate) struct SoftSolve {
    /// Inverse substep.
    pub inv_h: Real,
    /// Largest push-out speed.
    pub max_push: Real,
    /// Soft feedback (solve) or none (relax).
    pub use_bias: bool,
}

impl WideKernel for SoftSolve {
    #[inline(always)]
    fn run(&self, c: &mut WideConstraint, a: &mut WideBody, b: &mut WideBody) {
        super::solve_soft(c, a, b, self.inv_h, self.max_push, self.use_bias)
    }
}

/// The restitution pass ([`super::apply_restitution`] with this threshold).
pub(crate) struct Restitution {
    /// Approach speed below which no restitution applies.
    pub threshold: Real,
}

impl WideKernel for Restitution {
    #[inline(always)]
    fn run(&self, c: &mut WideConstraint, a: &mut WideBody, b: &mut WideBody) {
        super::apply_restitution(c, a, b, self.threshold)
    }
}

/// Any closure as a kernel (the tests' drivers).
#[cfg(test)]
pub(crate) struct Closure<F>(pub F);

#[cfg(test)]
impl<F: Fn(&mut WideConstraint, &mut WideBody, &mut WideBody)> WideKernel for Closure<F> {
    #[inline(always)]
    fn run(&self, c: &mut WideConstraint, a: &mut WideBody, b: &mut WideBody) {
        (self.0)(c, a, b)
    }
}

/// Gathers the bodies of `slots` into lanes (`b2GatherBodies`); padding lanes are a
/// motionless static body. Each body's `v, w, dp, dq` are twelve consecutive scalars
/// ([`SolverBody::state`]), read as three four-wide rows and transposed with three 4×4
/// transposes, which leave exactly the twelve lane vectors (`v.x … dq.z`).
#[inline(always)]
fn gather(bodies: &[SolverBody], slots: &[u32; LANES], inv_m: W) -> WideBody {
    let row = |s: u32| {
        if s == NO_SLOT {
            [[0.0; LANES]; 3]
        } else {
            bodies[s as usize].state()
        }
    };
    // Not `slots.map`: that call was left out of line in the stage executor (module
    // `soft_stages`), 100 M instructions in 60 steps of "1000 stack".
    let rows = [row(slots[0]), row(slots[1]), row(slots[2]), row(slots[3])];
    let t = |k: usize| W::transpose(rows.map(|r| W::new(r[k])));
    let ([vx, vy, vz, wx], [wy, wz, px, py], [pz, qx, qy, qz]) = (t(0), t(1), t(2));
    WideBody {
        v: V3 {
            x: vx,
            y: vy,
            z: vz,
        },
        w: V3 {
            x: wx,
            y: wy,
            z: wz,
        },
        dp: V3 {
            x: px,
            y: py,
            z: pz,
        },
        dq: V3 {
            x: qx,
            y: qy,
            z: qz,
        },
        inv_m,
    }
}

/// Writes the velocities of the lanes with `write[l]` (dynamic bodies) back
/// (`b2ScatterBodies`): two 4×4 transposes give each lane's `v, w` (and its unchanged
/// `dp.x, dp.y`) as two rows.
///
/// # Safety
/// `bodies` points to `len` solver bodies, and no other live reference touches the bodies
/// written during the call (the colouring guarantees it for one colour).
#[inline(always)]
unsafe fn scatter(
    body: &WideBody,
    bodies: *mut SolverBody,
    len: usize,
    slots: &[u32; LANES],
    write: &[bool; LANES],
) {
    let r0 = W::transpose([body.v.x, body.v.y, body.v.z, body.w.x]);
    let r1 = W::transpose([body.w.y, body.w.z, body.dp.x, body.dp.y]);
    for l in 0..LANES {
        if !write[l] {
            continue;
        }
        let s = slots[l] as usize;
        assert!(s < len);
        let target = &mut *bodies.add(s);
        target.set_velocities(r0[l].to_array(), r1[l].to_array());
    }
}

/// Raw access to the solver bodies while one colour is solved.
#[derive(Clone, Copy)]
pub(super) struct Bodies {
    pub(super) ptr: *mut SolverBody,
    pub(super) len: usize,
}

// SAFETY: used only to solve the wide constraints of one colour, which write disjoint
// dynamic bodies (the colouring guarantees it) and never write non-dynamic ones.
unsafe impl Send for Bodies {}
unsafe impl Sync for Bodies {}

impl Bodies {
    /// Gathers, runs `f` and scatters one wide constraint; `f` runs behind a call that is not
    /// inlined ([`kernel`]; on x86-64 with `ISA` not [`Isa::Base`], its copy compiled for
    /// that instruction set).
    ///
    /// # Safety
    /// No other live reference may touch the dynamic bodies of `c` during the call; the CPU
    /// has the instruction set `ISA` ([`Isa::detect`]).
    #[inline(always)]
    pub(super) unsafe fn run<K, A, const ISA: u8>(self, c: &mut WideConstraint, f: &K, active: &A)
    where
        K: WideKernel,
        A: Fn(&WideConstraint) -> bool,
    {
        if !active(c) {
            return;
        }
        let all = std::slice::from_raw_parts(self.ptr as *const SolverBody, self.len);
        let mut a = gather(all, &c.a, c.inv_m_a);
        let mut b = gather(all, &c.b, c.inv_m_b);
        match ISA {
            #[cfg(target_arch = "x86_64")]
            AVX => x86::kernel_avx(f, c, &mut a, &mut b),
            #[cfg(target_arch = "x86_64")]
            AVX512 => x86::kernel_avx512(f, c, &mut a, &mut b),
            _ => kernel(f, c, &mut a, &mut b),
        }
        scatter(&a, self.ptr, self.len, &c.a, &c.write_a);
        scatter(&b, self.ptr, self.len, &c.b, &c.write_b);
    }
}

/// One wide kernel (`f`: a warm start, solve or restitution pass of one wide constraint)
/// behind a call that is not inlined: inlined into the constraint loop, the kernels left
/// the gather's array maps out of line (+4.6 % instructions on "1000 stack", callgrind).
#[inline(never)]
fn kernel<K: WideKernel>(f: &K, c: &mut WideConstraint, a: &mut WideBody, b: &mut WideBody) {
    f.run(c, a, b)
}

/// [`Isa::Avx`] as the const parameter of [`Bodies::run`].
const AVX: u8 = 1;
/// [`Isa::Avx512`] as the const parameter of [`Bodies::run`].
const AVX512: u8 = 2;

/// The instruction set the wide passes run on, chosen at run time ([`Isa::detect`]). All
/// give the same bits: the lane arithmetic is `wide`'s four-lane SSE operations in every
/// case, the same IEEE-754 operations in the same order (no fused multiply-add: Rust never
/// contracts `a * b + c`, and `fma` is not enabled); only the encoding and the register
/// allocation differ. The passes keep the 24 lane vectors of the two bodies' state (and the
/// frame, the tracked linear velocities and the row data) live across a constraint's
/// points: on SSE2's 16 registers about a fifth of the kernel's instructions were stack
/// spills and register copies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Isa {
    /// The build's baseline (SSE2 on x86-64).
    Base,
    /// x86-64 with AVX: the same 16 registers, but three-operand (VEX) forms, which drop
    /// the register copies SSE's destructive two-operand forms need.
    Avx,
    /// x86-64 with AVX-512 F and VL: three-operand forms and 32 vector registers (EVEX), so
    /// the friction loop runs without a spill.
    Avx512,
}

impl Isa {
    /// The best instruction set of this CPU (`is_x86_feature_detected!` caches the answer,
    /// so this is a few loads and tests).
    #[inline]
    pub(crate) fn detect() -> Isa {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::is_x86_feature_detected as has;
            if has!("avx512f") && has!("avx512vl") {
                return Isa::Avx512;
            }
            if has!("avx") {
                return Isa::Avx;
            }
        }
        Isa::Base
    }

    /// Every instruction set this CPU can run, the baseline first (the tests run each).
    #[cfg(test)]
    pub(crate) fn available() -> Vec<Isa> {
        let best = Isa::detect();
        [Isa::Base, Isa::Avx, Isa::Avx512]
            .into_iter()
            .filter(|&i| i == Isa::Base || i == best || (i == Isa::Avx && best == Isa::Avx512))
            .collect()
    }
}

/// Runs `f` (where `active` holds) on the wide constraints `range` of `cons`, one after
/// another: one block of a colour in the stage-parallel soft step (module `stages`), on the
/// best instruction set of the CPU ([`Isa::detect`]).
///
/// # Safety
/// `cons` points to at least `range.end` wide constraints and `bodies` to `len` solver
/// bodies; during the call no other live reference touches those constraints or their
/// dynamic bodies (true for disjoint blocks of one colour).
#[inline]
pub(crate) unsafe fn solve_range<K, A>(
    cons: *mut WideConstraint,
    range: Range<usize>,
    bodies: *mut SolverBody,
    len: usize,
    f: &K,
    active: &A,
) where
    K: WideKernel,
    A: Fn(&WideConstraint) -> bool,
{
    solve_range_on(Isa::detect(), cons, range, bodies, len, f, active);
}

/// [`solve_range`] on the instruction set `isa`.
///
/// # Safety
/// As [`solve_range`]; the CPU has `isa` ([`Isa::detect`]).
pub(crate) unsafe fn solve_range_on<K, A>(
    isa: Isa,
    cons: *mut WideConstraint,
    range: Range<usize>,
    bodies: *mut SolverBody,
    len: usize,
    f: &K,
    active: &A,
) where
    K: WideKernel,
    A: Fn(&WideConstraint) -> bool,
{
    let shared = Bodies { ptr: bodies, len };
    match isa {
        #[cfg(target_arch = "x86_64")]
        Isa::Avx => x86::range_avx(cons, range, shared, f, active),
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => x86::range_avx512(cons, range, shared, f, active),
        _ => range_base(cons, range, shared, f, active),
    }
}

/// The constraint loop of [`solve_range`]. Not inlined, so each pass is one function in
/// which the gather and scatter are inlined (inlined into the caller's larger stage
/// executor they were not, which cost 5 % of the solver's instructions).
///
/// # Safety
/// As [`solve_range`].
#[inline(never)]
unsafe fn range_base<K, A>(c: *mut WideConstraint, range: Range<usize>, s: Bodies, f: &K, a: &A)
where
    K: WideKernel,
    A: Fn(&WideConstraint) -> bool,
{
    for i in range {
        s.run::<K, A, 0>(&mut *c.add(i), f, a);
    }
}

/// [`range_base`] and [`kernel`] compiled for AVX and for AVX-512 (see [`Isa`]).
#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::{Bodies, Range, WideBody, WideConstraint, WideKernel, AVX, AVX512};

    macro_rules! compiled_for {
        ($features:literal, $isa:ident, $range:ident, $kernel:ident) => {
            /// The constraint loop compiled for the instruction set named by its suffix.
            ///
            /// # Safety
            /// As `solve_range`, on a CPU with these features.
            #[inline(never)]
            #[target_feature(enable = $features)]
            pub(super) unsafe fn $range<K, A>(
                c: *mut WideConstraint,
                range: Range<usize>,
                s: Bodies,
                f: &K,
                a: &A,
            ) where
                K: WideKernel,
                A: Fn(&WideConstraint) -> bool,
            {
                for i in range {
                    s.run::<K, A, $isa>(&mut *c.add(i), f, a);
                }
            }

            /// One wide kernel compiled for the instruction set named by its suffix.
            ///
            /// # Safety
            /// The CPU has these features.
            #[inline(never)]
            #[target_feature(enable = $features)]
            pub(super) unsafe fn $kernel<K: WideKernel>(
                f: &K,
                c: &mut WideConstraint,
                a: &mut WideBody,
                b: &mut WideBody,
            ) {
                f.run(c, a, b)
            }
        };
    }

    compiled_for!("avx", AVX, range_avx, kernel_avx);
    compiled_for!("avx512f,avx512vl", AVX512, range_avx512, kernel_avx512);
}
