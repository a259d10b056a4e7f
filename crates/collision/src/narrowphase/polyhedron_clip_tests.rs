//! `clip`'s trivial accept against the full Sutherland–Hodgman loop (the oracle).

use super::{clip, Poly};
use crate::math::{Real, Vec3};

/// The clip as it was before the trivial accept: every corner through the full loop.
fn clip_full(poly: &[(Vec3, u32)], n: Vec3, d: Real, tag: u32) -> Poly {
    let mut out = Poly::new();
    let Some(&(first, _)) = poly.first() else {
        return out;
    };
    let first_d = n.dot(first) - d;
    let mut dp = first_d;
    for k in 0..poly.len() {
        let (p, ip) = poly[k];
        let (q, dq) = match poly.get(k + 1) {
            Some(&(q, _)) => (q, n.dot(q) - d),
            None => (first, first_d),
        };
        if dp <= 0.0 {
            out.push((p, ip));
        }
        if (dp < 0.0) != (dq < 0.0) && dp != dq {
            let t = dp / (dp - dq);
            out.push((p + (q - p) * t, (ip & 0xFFFF_FF00) | (tag & 0xFF)));
        }
        dp = dq;
    }
    out
}

/// `clip`, with the polygon kept when it reports a trivial accept.
fn clip_kept(poly: &[(Vec3, u32)], n: Vec3, d: Real, tag: u32) -> Poly {
    let mut out = Poly::new();
    out.push((Vec3::splat(Real::NAN), 0xDEAD));
    if clip(poly, n, d, tag, &mut out) {
        out
    } else {
        assert_eq!(out.len(), 1, "a trivial accept leaves the output untouched");
        poly.iter().copied().collect()
    }
}

fn same(a: &Poly, b: &Poly) -> bool {
    a.len() == b.len()
        && a.iter().zip(b.iter()).all(|(x, y)| {
            x.1 == y.1 && x.0.to_array().map(Real::to_bits) == y.0.to_array().map(Real::to_bits)
        })
}

/// A regular `k`-gon of radius `r` about `c` in the plane `z = c.z`, ids `0..k`.
fn ngon(k: usize, r: Real, c: Vec3) -> Poly {
    (0..k)
        .map(|i| {
            let a = i as Real * std::f64::consts::TAU as Real / k as Real;
            (c + Vec3::new(r * a.cos(), r * a.sin(), 0.0), i as u32)
        })
        .collect()
}

#[test]
fn trivial_accept_equals_the_full_clip_bit_for_bit() {
    let mut s = 0x9E37_79B9_7F4A_7C15_u64;
    let mut next = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((s >> 11) as f64 / (1u64 << 53) as f64) as Real * 2.0 - 1.0
    };
    let mut accepted = 0;
    let mut cut = 0;
    for centre in [Vec3::ZERO, Vec3::new(1.0e4, -2.0e4, 5.0e3)] {
        for k in [3, 4, 8, 12] {
            let poly = ngon(k, 1.0, centre);
            for _ in 0..200 {
                let n = Vec3::new(next(), next(), 0.2 * next());
                // Planes from far outside (all inside) to through the polygon.
                let d = n.dot(centre) + n.length() * (1.5 * next() + 0.5);
                let (a, b) = (clip_full(&poly, n, d, 7), clip_kept(&poly, n, d, 7));
                assert!(same(&a, &b), "{poly:?} {n:?} {d}");
                if a.len() == poly.len() && same(&a, &poly) {
                    accepted += 1;
                } else {
                    cut += 1;
                }
            }
        }
    }
    assert!(accepted > 100 && cut > 100, "{accepted} {cut}");
}

#[test]
fn corners_on_the_plane_and_degenerate_polygons_take_the_full_clip() {
    // Touching: one corner, or a whole edge, exactly on the plane; the full loop adds a
    // point there, which the trivial accept must not skip.
    let square: Poly = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .iter()
        .enumerate()
        .map(|(i, &(x, y))| (Vec3::new(x, y, 0.0), i as u32))
        .collect();
    for (n, d) in [
        (Vec3::X, 1.0),                  // an edge on the plane
        (Vec3::new(1.0, 1.0, 0.0), 2.0), // a corner on the plane
        (Vec3::X, 2.0),                  // strictly inside
        (Vec3::X, -2.0),                 // all outside
        (Vec3::ZERO, 0.0),               // zero normal: every distance is 0
        (Vec3::new(Real::NAN, 0.0, 0.0), 0.0),
    ] {
        let (a, b) = (clip_full(&square, n, d, 3), clip_kept(&square, n, d, 3));
        assert!(same(&a, &b), "{n:?} {d}: {a:?} vs {b:?}");
    }
    // Zero-size polygons (all corners at one point) and the empty polygon.
    let point: Poly = (0..4).map(|i| (Vec3::new(0.5, 0.5, 0.0), i)).collect();
    for d in [0.5, 1.0, 0.0] {
        let (a, b) = (
            clip_full(&point, Vec3::X, d, 1),
            clip_kept(&point, Vec3::X, d, 1),
        );
        assert!(same(&a, &b), "{d}");
    }
    let empty = Poly::new();
    assert!(same(
        &clip_full(&empty, Vec3::X, 0.0, 0),
        &clip_kept(&empty, Vec3::X, 0.0, 0)
    ));
}
