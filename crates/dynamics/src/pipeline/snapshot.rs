//! Snapshots: a whole [`World`] to bytes and back, exactly.
//!
//! Continuing from a restored snapshot gives bit-identical states to never stopping: the
//! bytes hold every piece of state a step reads — the body set (hot arrays, generations and
//! free list, sleep timers, pending forces and user wake-ups), the joints with their
//! warm-starting impulses and broken flags, the persistent contact manifolds with their
//! accumulated impulses and cached generation poses, the touching flags and events of every
//! pair, each collision object's pose, margin, filter and resting hint, which bodies landed
//! on another in the last step (their speculative margins depend on it), the accumulator of
//! [`World::step_simulation`] and the settings.
//!
//! **What is rebuilt instead of stored.** The broadphase's internal structures (trees, grid
//! cells, sweep lists) are not saved: every method reports exactly the pairs whose boxes
//! overlap, in sorted order (see `carom_collision::broadphase`), so re-inserting the objects
//! at the same slots, with the same boxes, gives the same pairs in the same order. Slots of
//! removed objects are re-created and removed again, so the next object added after a
//! restore takes the same slot as it would have without the snapshot (the lowest free one).
//! Object handle *generations* are not preserved (bodies are what users name; body handles
//! are preserved exactly). The solver's scratch arrays are rebuilt at every step anyway.
//!
//! **Shapes** are `Arc`s shared between bodies; each distinct shape (by pointer) is encoded
//! once and shared again on restore.
//!
//! **Format**: `b"CAROMWORLD"`, a format version (`u16` LE), the byte size of `Real` (a
//! snapshot restores only in the precision that wrote it), a 64-bit FNV-1a checksum of the
//! payload, then the payload (`serde` + `postcard`). Truncated or corrupt bytes, and decoded
//! data whose structure is inconsistent, give a [`CaromError`], never a panic. As with any
//! deserialiser, bytes from untrusted sources should be treated with care: shapes are checked
//! by an optional validator ([`World::from_bytes_with`]).
//!
//! Limits (documented, not hidden): a snapshot taken after a body was removed *and before the
//! next step* drops that body's pending `End` contact events; one taken after a teleport
//! (`set_pose`) and before the next step starts from the broadphase pairs at the new pose.

use super::{PipelineParams, PipelineReport, World};
use crate::body_set::{BodyHandle, BodySet};
use crate::joint::{JointHandle, JointSet};
use crate::world::{DynamicsWorld, StepReport, WorldParams};
use carom_collision::broadphase::{Filter, Method};
use carom_collision::math::{Isometry, Real};
use carom_collision::narrowphase::{
    ContactEvent, ContactEventKind, ContactManifold as NarrowManifold, ManifoldConfig,
};
use carom_collision::shape::{Shape, Sphere};
use carom_collision::world::ObjectHandle;
use carom_collision::{CaromError, Result};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// Tag at the start of every world snapshot.
pub const SNAPSHOT_MAGIC: &[u8; 10] = b"CAROMWORLD";
/// Version of the snapshot format written by [`World::to_bytes`] (2: manifolds keep their
/// separation certificate, `ContactManifold::apart`; 3: and their GJK simplex,
/// `ContactManifold::warm`; 4: and which bodies landed in the last step; 5: and each body's
/// rest anchor, `BodyInfo::rest_position` and `rest_rotation`, with the sleep drift, and
/// `PipelineParams::spin_workers`). The payload is
/// postcard, which has no field names, so a snapshot of another version is refused rather
/// than misread.
pub const SNAPSHOT_VERSION: u16 = 5;
const HEADER_LEN: usize = 10 + 2 + 1 + 8;

#[derive(Serialize, Deserialize)]
struct ObjectSnap {
    index: u32,
    body: u32,
    shape: u32,
    pose: Isometry,
    filter: Filter,
    margin: Real,
    resting: bool,
}

#[derive(Serialize, Deserialize)]
struct PairSnap {
    a: u32,
    b: u32,
    manifold: NarrowManifold,
    touching: bool,
    sensor: bool,
}

#[derive(Serialize, Deserialize)]
struct EventSnap {
    a: u32,
    b: u32,
    kind: u8,
    sensor: bool,
}

#[derive(Serialize, Deserialize)]
struct ReportSnap {
    pairs: usize,
    manifolds: usize,
    contact_points: usize,
    woken: Vec<BodyHandle>,
    slept: Vec<BodyHandle>,
    broken_joints: Vec<JointHandle>,
}

#[derive(Serialize, Deserialize)]
struct Snapshot {
    dynamics_params: WorldParams,
    broadphase: String,
    manifold: ManifoldConfig,
    speculative: bool,
    spin_workers: bool,
    shapes: Vec<Shape>,
    bodies: BodySet,
    body_shapes: Vec<Option<u32>>,
    joints: JointSet,
    object_slots: u32,
    objects: Vec<ObjectSnap>,
    radius: Vec<Real>,
    resting: Vec<bool>,
    landed: Vec<bool>,
    accumulator: Real,
    pairs: Vec<PairSnap>,
    events: Vec<EventSnap>,
    report: ReportSnap,
}

fn corrupt(reason: impl Into<String>) -> CaromError {
    CaromError::Parse {
        what: "carom world snapshot".to_string(),
        reason: reason.into(),
    }
}

/// 64-bit FNV-1a.
fn checksum(data: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in data {
        h ^= b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

fn event_kind(k: ContactEventKind) -> u8 {
    match k {
        ContactEventKind::Begin => 0,
        ContactEventKind::Persist => 1,
        ContactEventKind::End => 2,
    }
}

/// Interns shared shapes by pointer, in first-seen order.
#[derive(Default)]
struct ShapeTable {
    ptrs: Vec<*const Shape>,
    shapes: Vec<Shape>,
}

impl ShapeTable {
    fn intern(&mut self, s: &Arc<Shape>) -> u32 {
        let p = Arc::as_ptr(s);
        if let Some(i) = self.ptrs.iter().position(|&q| q == p) {
            return i as u32;
        }
        self.ptrs.push(p);
        self.shapes.push((**s).clone());
        (self.shapes.len() - 1) as u32
    }
}

impl World {
    /// Saves the whole world to bytes (see [`crate::pipeline::snapshot`] for the format and
    /// what is stored). [`World::from_bytes`] restores it exactly.
    pub fn to_bytes(&self) -> Result<Vec<u8>> {
        let mut table = ShapeTable::default();
        let bodies = self.dynamics.bodies();
        let body_shapes: Vec<Option<u32>> = bodies
            .info
            .iter()
            .map(|info| info.shape.as_ref().map(|s| table.intern(s)))
            .collect();
        let mut objects = Vec::new();
        for (h, o) in self.collision.iter() {
            let Some(body) = self.body_of_object(h) else {
                return Err(corrupt(format!("object {h:?} has no body")));
            };
            objects.push(ObjectSnap {
                index: h.index,
                body: body.index,
                shape: table.intern(&o.shape),
                pose: o.pose,
                filter: o.filter,
                margin: o.margin,
                resting: o.resting,
            });
        }
        let live = |h: ObjectHandle| self.collision.get(h).is_ok();
        let np = self.collision.narrowphase();
        // A pair whose manifold holds nothing (no points, no cached state) and that is not
        // touching is left out: restoring gives such a pair a fresh manifold anyway, so the
        // bytes of a restored world equal the bytes it was restored from (a world not yet
        // stepped has no pairs; its restored copy has them, empty, after the rebuild).
        let pairs = np
            .pairs()
            .filter(|p| live(p.a) && live(p.b))
            .filter(|p| p.touching || p.manifold != NarrowManifold::default())
            .map(|p| PairSnap {
                a: p.a.index,
                b: p.b.index,
                manifold: p.manifold.clone(),
                touching: p.touching,
                sensor: p.sensor,
            })
            .collect();
        let events = np
            .events()
            .iter()
            .filter(|e| live(e.a) && live(e.b))
            .map(|e| EventSnap {
                a: e.a.index,
                b: e.b.index,
                kind: event_kind(e.kind),
                sensor: e.sensor,
            })
            .collect();
        let r = &self.report;
        let snap = Snapshot {
            dynamics_params: self.params.dynamics,
            broadphase: self.params.broadphase.name().to_string(),
            manifold: self.params.manifold,
            speculative: self.params.speculative,
            spin_workers: self.params.spin_workers,
            shapes: table.shapes,
            bodies: bodies.clone(),
            body_shapes,
            joints: self.dynamics.joints().clone(),
            object_slots: self.body_of.len() as u32,
            objects,
            radius: self.radius.clone(),
            resting: self.resting.clone(),
            landed: self.landed.clone(),
            accumulator: self.accumulator,
            pairs,
            events,
            report: ReportSnap {
                pairs: r.pairs,
                manifolds: r.manifolds,
                contact_points: r.contact_points,
                woken: r.dynamics.woken.clone(),
                slept: r.dynamics.slept.clone(),
                broken_joints: r.dynamics.broken_joints.clone(),
            },
        };
        let payload = postcard::to_allocvec(&snap).map_err(|e| corrupt(e.to_string()))?;
        let mut out = Vec::with_capacity(HEADER_LEN + payload.len());
        out.extend_from_slice(SNAPSHOT_MAGIC);
        out.extend_from_slice(&SNAPSHOT_VERSION.to_le_bytes());
        out.push(std::mem::size_of::<Real>() as u8);
        out.extend_from_slice(&checksum(&payload).to_le_bytes());
        out.extend_from_slice(&payload);
        Ok(out)
    }

    /// Restores a world saved by [`World::to_bytes`]. Bad, truncated or corrupt bytes give
    /// [`CaromError::Parse`] (or `InvalidValue` for inconsistent content).
    pub fn from_bytes(data: &[u8]) -> Result<World> {
        Self::from_bytes_with(data, |_| Ok(()))
    }

    /// [`World::from_bytes`] with a validator run on every decoded shape before it is used
    /// (the Python bindings re-check shapes through their constructors).
    pub fn from_bytes_with(
        data: &[u8],
        validate_shape: impl Fn(&Shape) -> Result<()>,
    ) -> Result<World> {
        let snap = decode(data)?;
        for s in &snap.shapes {
            validate_shape(s)?;
        }
        restore(snap)
    }
}

fn decode(data: &[u8]) -> Result<Snapshot> {
    let rest = data
        .strip_prefix(SNAPSHOT_MAGIC.as_slice())
        .ok_or_else(|| corrupt("missing header: not bytes made by World.to_bytes()"))?;
    if rest.len() < HEADER_LEN - SNAPSHOT_MAGIC.len() {
        return Err(corrupt(format!("truncated header ({} bytes)", data.len())));
    }
    let version = u16::from_le_bytes([rest[0], rest[1]]);
    if version != SNAPSHOT_VERSION {
        return Err(corrupt(format!(
            "format version {version}, this build reads version {SNAPSHOT_VERSION}"
        )));
    }
    let real = rest[2] as usize;
    if real != std::mem::size_of::<Real>() {
        return Err(corrupt(format!(
            "written with {}-bit reals, this build uses {}-bit reals",
            real * 8,
            std::mem::size_of::<Real>() * 8
        )));
    }
    let mut sum = [0u8; 8];
    sum.copy_from_slice(&rest[3..11]);
    let payload = &rest[11..];
    if checksum(payload) != u64::from_le_bytes(sum) {
        return Err(corrupt(format!(
            "checksum mismatch: truncated or corrupt ({} payload bytes)",
            payload.len()
        )));
    }
    let (snap, tail): (Snapshot, &[u8]) =
        postcard::take_from_bytes(payload).map_err(|e| corrupt(e.to_string()))?;
    if !tail.is_empty() {
        return Err(corrupt(format!("{} trailing bytes", tail.len())));
    }
    Ok(snap)
}

fn restore(snap: Snapshot) -> Result<World> {
    let params = PipelineParams {
        dynamics: snap.dynamics_params,
        broadphase: snap.broadphase.parse::<Method>()?,
        manifold: snap.manifold,
        speculative: snap.speculative,
        spin_workers: snap.spin_workers,
    };
    let mut world = World::new(params)?;
    let shapes: Vec<Arc<Shape>> = snap.shapes.into_iter().map(Arc::new).collect();
    let shape = |i: u32| {
        shapes
            .get(i as usize)
            .cloned()
            .ok_or_else(|| corrupt(format!("shape index {i} out of range")))
    };
    let mut bodies = snap.bodies;
    let cap = bodies.capacity();
    if snap.body_shapes.len() != cap
        || snap.radius.len() != cap
        || snap.resting.len() != cap
        || snap.landed.len() > cap
    {
        return Err(corrupt("per-body arrays of different lengths"));
    }
    for (i, s) in snap.body_shapes.iter().enumerate() {
        let info = &mut bodies.info[i];
        info.shape = s.map(shape).transpose()?;
        info.reach = crate::body_set::reach(info.shape.as_deref(), info.local_com);
    }
    world.dynamics = DynamicsWorld::from_parts(params.dynamics, bodies, snap.joints)?;
    world.radius = snap.radius;
    world.resting = snap.resting;
    world.landed = snap.landed;
    world.object_of = vec![None; cap];
    world.accumulator = snap.accumulator;
    if !world.accumulator.is_finite() {
        return Err(corrupt("non-finite accumulator"));
    }

    // Objects at their slots; dead slots get a placeholder that is removed again.
    let slots = snap.object_slots as usize;
    let mut by_slot: Vec<Option<&ObjectSnap>> = vec![None; slots];
    for o in &snap.objects {
        let k = o.index as usize;
        if k >= slots || by_slot[k].is_some() {
            return Err(corrupt(format!("object slot {k} out of range or repeated")));
        }
        by_slot[k] = Some(o);
    }
    world.body_of = vec![None; slots];
    let placeholder = Arc::new(Shape::from(Sphere::new(1.0)?));
    let nothing = Filter {
        group: 0,
        mask: 0,
        ..Filter::default()
    };
    let mut dead = Vec::new();
    for (k, o) in by_slot.iter().enumerate() {
        let h = match o {
            Some(o) => world.collision.add(shape(o.shape)?, o.pose, o.filter)?,
            None => world
                .collision
                .add(placeholder.clone(), Isometry::IDENTITY, nothing)?,
        };
        if h.index as usize != k {
            return Err(corrupt(format!("object slot {k} restored at {}", h.index)));
        }
        let Some(o) = o else {
            dead.push(h);
            continue;
        };
        world.collision.set_pose_with_margin(h, o.pose, o.margin)?;
        // Resting during the rebuild update, so it generates no contacts that the saved
        // manifolds would replace anyway; the saved hint is set after it.
        world.collision.set_resting(h, true)?;
        let b = o.body as usize;
        if !world.dynamics.bodies().is_alive_checked(b) || world.object_of[b].is_some() {
            return Err(corrupt(format!("object {k} names body slot {b}")));
        }
        world.object_of[b] = Some(h);
        world.body_of[k] = Some(world.dynamics.bodies().handle_of(b));
    }
    for h in dead {
        world.collision.remove(h)?;
    }
    world.exclude_jointed_pairs()?;
    world.collision.update()?;
    for o in &snap.objects {
        if let Some(h) = world.object_of[o.body as usize] {
            world.collision.set_resting(h, o.resting)?;
        }
    }

    // The persistent manifolds: saved state for the saved pairs, a fresh manifold for a pair
    // the saved world did not have yet (as a newly added pair would get).
    let handle_at = |world: &World, k: u32| -> Result<ObjectHandle> {
        world
            .body_of
            .get(k as usize)
            .copied()
            .flatten()
            .and_then(|b| world.object_of[b.index as usize])
            .ok_or_else(|| corrupt(format!("pair names object slot {k}")))
    };
    let mut saved = snap.pairs.into_iter().peekable();
    for p in world.collision.narrowphase_mut().pairs_mut() {
        let key = (p.a.index, p.b.index);
        while saved.peek().is_some_and(|s| (s.a, s.b) < key) {
            saved.next();
        }
        match saved.next_if(|s| (s.a, s.b) == key) {
            Some(s) => {
                p.manifold = s.manifold;
                p.touching = s.touching;
                p.sensor = s.sensor;
            }
            None => {
                p.manifold = NarrowManifold::default();
                p.touching = false;
                p.sensor = false;
            }
        }
    }
    let mut events = Vec::with_capacity(snap.events.len());
    for e in &snap.events {
        let kind = match e.kind {
            0 => ContactEventKind::Begin,
            1 => ContactEventKind::Persist,
            2 => ContactEventKind::End,
            k => return Err(corrupt(format!("unknown event kind {k}"))),
        };
        events.push(ContactEvent {
            a: handle_at(&world, e.a)?,
            b: handle_at(&world, e.b)?,
            kind,
            sensor: e.sensor,
        });
    }
    world.collision.narrowphase_mut().restore_events(events);
    let r = snap.report;
    world.report = PipelineReport {
        pairs: r.pairs,
        manifolds: r.manifolds,
        contact_points: r.contact_points,
        dynamics: StepReport {
            woken: r.woken,
            slept: r.slept,
            broken_joints: r.broken_joints,
            ..Default::default()
        },
        ..Default::default()
    };
    Ok(world)
}

#[cfg(test)]
mod tests {
    //! Payloads that pass the checksum but carry inconsistent content are rejected by the
    //! structural checks, never by a panic later.
    use super::*;
    use crate::body::BodyDesc;
    use carom_collision::math::Vec3;
    use carom_collision::shape::Cuboid;

    fn world() -> World {
        let mut w = World::new(PipelineParams::default()).unwrap();
        let s = Arc::new(Shape::from(Cuboid::new(Vec3::splat(0.5)).unwrap()));
        w.add_body(&BodyDesc::fixed(s.clone(), Isometry::IDENTITY))
            .unwrap();
        for i in 0..3 {
            let p = Isometry::from_translation(Vec3::new(0.0, 1.0 + i as Real, 0.0));
            w.add_body(&BodyDesc::dynamic(s.clone(), p, 100.0)).unwrap();
        }
        w.step(1.0 / 60.0).unwrap();
        w
    }

    fn encode(snap: &Snapshot) -> Vec<u8> {
        let payload = postcard::to_allocvec(snap).unwrap();
        let mut out = SNAPSHOT_MAGIC.to_vec();
        out.extend_from_slice(&SNAPSHOT_VERSION.to_le_bytes());
        out.push(std::mem::size_of::<Real>() as u8);
        out.extend_from_slice(&checksum(&payload).to_le_bytes());
        out.extend_from_slice(&payload);
        out
    }

    #[test]
    fn inconsistent_content_is_an_error() {
        let bytes = world().to_bytes().unwrap();
        assert_eq!(
            encode(&decode(&bytes).unwrap()),
            bytes,
            "test encoder matches"
        );
        type Tamper = (&'static str, fn(&mut Snapshot));
        let tamper: [Tamper; 9] = [
            ("shape index", |s| s.body_shapes[1] = Some(99)),
            ("object shape", |s| s.objects[0].shape = 7),
            ("object body", |s| s.objects[1].body = 40),
            ("object slot", |s| s.objects[1].index = 1000),
            ("repeated slot", |s| s.objects[2].index = s.objects[1].index),
            ("per-body arrays", |s| {
                s.radius.pop();
            }),
            ("accumulator", |s| s.accumulator = Real::NAN),
            ("method", |s| s.broadphase = "octree".into()),
            ("event kind", |s| {
                s.events.push(EventSnap {
                    a: 0,
                    b: 1,
                    kind: 9,
                    sensor: false,
                })
            }),
        ];
        for (what, f) in tamper {
            let mut snap = decode(&bytes).unwrap();
            f(&mut snap);
            assert!(
                World::from_bytes(&encode(&snap)).is_err(),
                "{what} accepted"
            );
        }
        // Body sets with slots out of range or arrays of different lengths.
        let mut snap = decode(&bytes).unwrap();
        snap.bodies.woken_by_user.push(999);
        assert!(
            World::from_bytes(&encode(&snap)).is_err(),
            "bad woken slot accepted"
        );
        let mut snap = decode(&bytes).unwrap();
        snap.bodies.position.pop();
        assert!(
            World::from_bytes(&encode(&snap)).is_err(),
            "short array accepted"
        );
        // The untouched payload still restores.
        assert!(World::from_bytes(&encode(&decode(&bytes).unwrap())).is_ok());
    }
}
