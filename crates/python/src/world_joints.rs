//! Joints of `carom.World`: the Python arguments of `add_joint` turned into a
//! `carom_dynamics::JointDesc`, and joint handles as ints.
//!
//! One entry point for every joint type the core has (`kind` = "ball", "hinge",
//! "cone_twist", "slider", "fixed", "6dof"), with keyword options that apply to some kinds
//! only; an option given to a kind that has no use for it is an error naming it, so a typo
//! never silently builds a different joint.

use crate::convert::scalar;
use crate::errors::invalid;
use crate::pose::extract_isometry;
use carom_collision::math::Real;
use carom_dynamics::{
    Axis, AxisMode, BodyHandle, JointDesc, JointHandle, JointKind, Motor, Spring,
};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

/// A joint handle as a Python int (generation in the high 32 bits).
pub(crate) fn joint_bits(h: JointHandle) -> u64 {
    (u64::from(h.generation) << 32) | u64::from(h.index)
}

/// The joint handle of a Python int.
pub(crate) fn joint_handle(b: u64) -> JointHandle {
    JointHandle {
        index: b as u32,
        generation: (b >> 32) as u32,
    }
}

/// The keyword options of `World.add_joint`.
pub(crate) struct JointOptions<'a, 'py> {
    pub frame_a: Option<&'a Bound<'py, PyAny>>,
    pub frame_b: Option<&'a Bound<'py, PyAny>>,
    pub limits: Option<(f64, f64)>,
    pub motor: Option<(f64, f64)>,
    pub swing1: Option<f64>,
    pub swing2: Option<f64>,
    pub twist: Option<f64>,
    pub linear: Option<&'a Bound<'py, PyAny>>,
    pub angular: Option<&'a Bound<'py, PyAny>>,
    pub break_impulse: f64,
    pub disable_collisions: bool,
}

fn limits_arg(name: &str, l: Option<(f64, f64)>) -> PyResult<Option<(Real, Real)>> {
    l.map(|(lo, hi)| {
        Ok((
            scalar(&format!("{name}[0]"), lo)?,
            scalar(&format!("{name}[1]"), hi)?,
        ))
    })
    .transpose()
}

fn motor_arg(name: &str, m: Option<(f64, f64)>) -> PyResult<Option<Motor>> {
    m.map(|(speed, max_force)| {
        Ok(Motor {
            speed: scalar(&format!("{name}[0] (speed)"), speed)?,
            max_force: scalar(&format!("{name}[1] (max_force)"), max_force)?,
        })
    })
    .transpose()
}

/// One 6-DOF axis: `"locked"` (or None), `"free"`, `(low, high)`, or a dict with `limits`
/// (`(low, high)`, `"free"` or `"locked"`), `motor` `(speed, max_force)` and `spring`
/// `(hertz, damping_ratio, rest)`.
fn axis_arg(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Axis> {
    if obj.is_none() {
        return Ok(Axis::default());
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        let mut axis = Axis::default();
        for (k, v) in d.iter() {
            let key: String = k.extract()?;
            match key.as_str() {
                "limits" | "mode" => axis.mode = axis_arg(&v, name)?.mode,
                "motor" => axis.motor = motor_arg(&format!("{name}.motor"), Some(v.extract()?))?,
                "spring" => {
                    let (hz, zeta, rest): (f64, f64, f64) = v.extract()?;
                    axis.spring = Some(Spring {
                        hertz: scalar(&format!("{name}.spring[0] (hertz)"), hz)?,
                        damping_ratio: scalar(&format!("{name}.spring[1] (damping_ratio)"), zeta)?,
                        rest: scalar(&format!("{name}.spring[2] (rest)"), rest)?,
                    });
                }
                other => {
                    return Err(invalid(format!(
                        "{name}: unknown key {other:?} (expected limits, motor, spring)"
                    )))
                }
            }
        }
        return Ok(axis);
    }
    if let Ok(s) = obj.cast::<PyString>() {
        let text: String = s.extract()?;
        let mode = match text.as_str() {
            "locked" => AxisMode::Locked,
            "free" => AxisMode::Free,
            other => {
                return Err(invalid(format!(
                    "{name} = {other:?}: expected \"locked\", \"free\", (low, high) or a dict"
                )))
            }
        };
        return Ok(Axis {
            mode,
            ..Default::default()
        });
    }
    let (lo, hi): (f64, f64) = obj.extract().map_err(|_| {
        pyo3::exceptions::PyTypeError::new_err(format!(
            "{name}: expected \"locked\", \"free\", (low, high) or a dict"
        ))
    })?;
    let (low, high) = limits_arg(name, Some((lo, hi)))?.unwrap_or_default();
    Ok(Axis {
        mode: AxisMode::Limited { low, high },
        ..Default::default()
    })
}

fn axes_arg(obj: Option<&Bound<'_, PyAny>>, name: &str) -> PyResult<[Axis; 3]> {
    let Some(obj) = obj else {
        return Ok([Axis::default(); 3]);
    };
    let items: Vec<Bound<'_, PyAny>> = obj.try_iter()?.collect::<PyResult<_>>()?;
    if items.len() != 3 {
        return Err(invalid(format!(
            "{name} must list 3 axes (x, y, z), got {}",
            items.len()
        )));
    }
    let mut out = [Axis::default(); 3];
    for (k, it) in items.iter().enumerate() {
        out[k] = axis_arg(it, &format!("{name}[{k}]"))?;
    }
    Ok(out)
}

/// Builds the joint description (validated by the core when the joint is created).
pub(crate) fn joint_desc(
    kind: &str,
    a: BodyHandle,
    b: BodyHandle,
    o: &JointOptions<'_, '_>,
) -> PyResult<JointDesc> {
    let unused = |names: &[(&str, bool)]| -> PyResult<()> {
        match names.iter().find(|(_, given)| *given) {
            Some((n, _)) => Err(invalid(format!("{n} does not apply to a {kind:?} joint"))),
            None => Ok(()),
        }
    };
    let lm = [("limits", o.limits.is_some()), ("motor", o.motor.is_some())];
    let cone = [
        ("swing1", o.swing1.is_some()),
        ("swing2", o.swing2.is_some()),
        ("twist", o.twist.is_some()),
    ];
    let six = [
        ("linear", o.linear.is_some()),
        ("angular", o.angular.is_some()),
    ];
    let jk = match kind {
        "ball" | "fixed" => {
            unused(&lm)?;
            unused(&cone)?;
            unused(&six)?;
            if kind == "ball" {
                JointKind::Ball
            } else {
                JointKind::Fixed
            }
        }
        "hinge" | "slider" => {
            unused(&cone)?;
            unused(&six)?;
            let limits = limits_arg("limits", o.limits)?;
            let motor = motor_arg("motor", o.motor)?;
            if kind == "hinge" {
                JointKind::Hinge { limits, motor }
            } else {
                JointKind::Slider { limits, motor }
            }
        }
        "cone_twist" => {
            unused(&lm)?;
            unused(&six)?;
            let req = |n: &str, v: Option<f64>| -> PyResult<Real> {
                scalar(
                    n,
                    v.ok_or_else(|| invalid(format!("a cone_twist joint needs {n}")))?,
                )
            };
            JointKind::ConeTwist {
                swing1: req("swing1", o.swing1)?,
                swing2: req("swing2", o.swing2)?,
                twist: req("twist", o.twist)?,
            }
        }
        "6dof" => {
            unused(&lm)?;
            unused(&cone)?;
            JointKind::Generic6Dof {
                linear: axes_arg(o.linear, "linear")?,
                angular: axes_arg(o.angular, "angular")?,
            }
        }
        other => {
            return Err(invalid(format!(
                "kind = {other:?}: expected \"ball\", \"hinge\", \"cone_twist\", \"slider\", \
                 \"fixed\" or \"6dof\""
            )))
        }
    };
    Ok(JointDesc {
        body_a: a,
        body_b: b,
        frame_a: extract_isometry(o.frame_a, "frame_a")?,
        frame_b: extract_isometry(o.frame_b, "frame_b")?,
        kind: jk,
        break_impulse: scalar("break_impulse", o.break_impulse)?,
        disable_collisions: o.disable_collisions,
    })
}
