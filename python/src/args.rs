//! The functions' arguments read from Python objects, so that a bad one
//! is an `InputError` naming the argument and what to give instead,
//! never a `TypeError`, an `OverflowError` or `True` taken for 1.
//!
//! Each argument has a small extractor (`#[pyo3(from_py_with = ...)]`)
//! that names it; `None` is the argument left out.

use std::path::PathBuf;
use std::time::Duration;

use chatterspice::netlist::ContactElement;
use chatterspice::pipeline::Coupling;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyFloat, PyInt, PyString};

use crate::error::Failure;

/// The Python type of `obj`, for messages.
fn type_name(obj: &Bound<'_, PyAny>) -> String {
    obj.get_type()
        .name()
        .map_or_else(|_| "?".to_owned(), |n| n.to_string())
}

fn refuse(name: &str, obj: &Bound<'_, PyAny>, want: &str) -> PyErr {
    let shown = obj
        .repr()
        .map_or_else(|_| type_name(obj), |r| r.to_string());
    Failure::input(format!(
        "{name} = {shown} ({}): give {want}",
        type_name(obj)
    ))
    .into()
}

/// A `str` or `os.PathLike`.
fn path(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Option<PathBuf>> {
    if obj.is_none() {
        return Ok(None);
    }
    let want = "a path: a str or an os.PathLike such as pathlib.Path";
    if obj.is_instance_of::<PyBool>() {
        return Err(refuse(name, obj, want));
    }
    let os = obj.py().import("os")?;
    let Ok(text) = os.call_method1("fspath", (obj,)) else {
        return Err(refuse(name, obj, want));
    };
    let text = if text.is_instance_of::<PyString>() {
        text
    } else {
        os.call_method1("fsdecode", (text,))?
    };
    Ok(Some(text.extract::<PathBuf>()?))
}

/// A whole number of at least `min`.
fn count(obj: &Bound<'_, PyAny>, name: &str, min: u64, what: &str) -> PyResult<Option<u64>> {
    if obj.is_none() {
        return Ok(None);
    }
    let want = format!("a whole number ≥ {min}: {what}");
    // numpy's integers are not int, but index as one.
    if obj.is_instance_of::<PyBool>()
        || !(obj.is_instance_of::<PyInt>() || obj.hasattr("__index__")?)
    {
        return Err(refuse(name, obj, &want));
    }
    let index = obj.call_method0("__index__")?;
    match index.extract::<u64>() {
        Ok(n) if n >= min => Ok(Some(n)),
        _ => Err(refuse(name, obj, &want)),
    }
}

/// A number of seconds, finite and > 0.
fn seconds(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Duration> {
    let want = "the wall-clock limit of each ngspice run in seconds, > 0 (e.g. 60.0)";
    if obj.is_instance_of::<PyBool>()
        || !(obj.is_instance_of::<PyFloat>() || obj.is_instance_of::<PyInt>())
    {
        return Err(refuse(name, obj, want));
    }
    let value: f64 = obj.extract()?;
    match Duration::try_from_secs_f64(value) {
        Ok(d) if value > 0.0 => Ok(d),
        _ => Err(refuse(name, obj, want)),
    }
}

/// `True` or `False` (numpy's booleans too).
fn flag(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<bool> {
    if obj.is_instance_of::<PyBool>() {
        return obj.extract();
    }
    let numpy_bool = obj
        .py()
        .import("numpy")
        .and_then(|np| np.getattr("bool_"))
        .is_ok_and(|t| obj.is_instance(&t).unwrap_or(false));
    if numpy_bool {
        return obj.call_method0("__bool__")?.extract();
    }
    Err(refuse(name, obj, "True or False"))
}

/// A `str`.
fn text(obj: &Bound<'_, PyAny>, name: &str, what: &str) -> PyResult<Option<String>> {
    if obj.is_none() {
        return Ok(None);
    }
    if !obj.is_instance_of::<PyString>() {
        return Err(refuse(name, obj, what));
    }
    Ok(Some(obj.extract()?))
}

/// A number.
fn number(obj: &Bound<'_, PyAny>, name: &str, what: &str) -> PyResult<Option<f64>> {
    if obj.is_none() {
        return Ok(None);
    }
    if obj.is_instance_of::<PyBool>() {
        return Err(refuse(name, obj, what));
    }
    obj.extract::<f64>()
        .map(Some)
        .map_err(|_| refuse(name, obj, what))
}

pub fn path_arg(obj: &Bound<'_, PyAny>) -> PyResult<Option<PathBuf>> {
    path(obj, "path")
}

/// The required path of `capture` and `read_raw`.
pub fn file_arg(obj: &Bound<'_, PyAny>) -> PyResult<PathBuf> {
    path(obj, "path")?.ok_or_else(|| refuse("path", obj, "the file's path"))
}

pub fn origin_arg(obj: &Bound<'_, PyAny>) -> PyResult<Option<PathBuf>> {
    path(obj, "origin")
}

pub fn measured_arg(obj: &Bound<'_, PyAny>) -> PyResult<Option<PathBuf>> {
    path(obj, "measured")
}

pub fn capture_arg(obj: &Bound<'_, PyAny>) -> PyResult<Option<PathBuf>> {
    path(obj, "capture")
}

pub fn toml_text_arg(obj: &Bound<'_, PyAny>) -> PyResult<Option<String>> {
    text(obj, "toml_text", "the scenario's TOML as a str")
}

pub fn channel_arg(obj: &Bound<'_, PyAny>) -> PyResult<Option<String>> {
    text(obj, "channel", "the channel's name as a str, e.g. \"CH1\"")
}

pub fn closed_arg(obj: &Bound<'_, PyAny>) -> PyResult<Option<String>> {
    text(
        obj,
        "closed",
        "\"high\" or \"low\", the level of the closed contact",
    )
}

pub fn low_arg(obj: &Bound<'_, PyAny>) -> PyResult<Option<f64>> {
    number(obj, "low", "the lower threshold in volts")
}

pub fn high_arg(obj: &Bound<'_, PyAny>) -> PyResult<Option<f64>> {
    number(obj, "high", "the upper threshold in volts")
}

pub fn timeout_arg(obj: &Bound<'_, PyAny>) -> PyResult<Duration> {
    seconds(obj, "timeout")
}

pub fn samples_arg(obj: &Bound<'_, PyAny>) -> PyResult<Option<u64>> {
    count(obj, "samples", 1, "how many samples to draw")
}

pub fn seed_arg(obj: &Bound<'_, PyAny>) -> PyResult<Option<u64>> {
    count(obj, "seed", 0, "the seed of the draw")
}

pub fn jobs_arg(obj: &Bound<'_, PyAny>) -> PyResult<Option<u64>> {
    count(obj, "jobs", 1, "how many samples run at once")
}

pub fn ideal_arg(obj: &Bound<'_, PyAny>) -> PyResult<bool> {
    flag(obj, "ideal")
}

pub fn mechanics_only_arg(obj: &Bound<'_, PyAny>) -> PyResult<bool> {
    flag(obj, "mechanics_only")
}

pub fn out_arg(obj: &Bound<'_, PyAny>) -> PyResult<Option<PathBuf>> {
    path(obj, "out")
}

pub fn resume_arg(obj: &Bound<'_, PyAny>) -> PyResult<Option<PathBuf>> {
    path(obj, "resume")
}

pub fn force_arg(obj: &Bound<'_, PyAny>) -> PyResult<bool> {
    flag(obj, "force")
}

pub fn keep_workdir_arg(obj: &Bound<'_, PyAny>) -> PyResult<bool> {
    flag(obj, "keep_workdir")
}

/// A callable, or None.
pub fn progress_arg<'py>(obj: &Bound<'py, PyAny>) -> PyResult<Option<Bound<'py, PyAny>>> {
    if obj.is_none() {
        return Ok(None);
    }
    if !obj.is_callable() {
        return Err(refuse(
            "progress",
            obj,
            "a callable taking (done, total), or None",
        ));
    }
    Ok(Some(obj.clone()))
}

/// Dotted keys: one `str`, or an iterable of them.
pub fn free_arg(obj: &Bound<'_, PyAny>) -> PyResult<Option<Vec<String>>> {
    let want = "a dotted key (\"surface.damping\") or a list of them";
    if obj.is_none() {
        return Ok(None);
    }
    if obj.is_instance_of::<PyString>() {
        return Ok(Some(vec![obj.extract()?]));
    }
    let Ok(items) = obj.try_iter() else {
        return Err(refuse("free", obj, want));
    };
    let mut keys = Vec::new();
    for item in items {
        let item = item?;
        if !item.is_instance_of::<PyString>() {
            return Err(refuse("free", &item, want));
        }
        keys.push(item.extract()?);
    }
    Ok(Some(keys))
}

/// A whole number within `range`, as the command line's option of the
/// same name takes it.
fn bounded(
    obj: &Bound<'_, PyAny>,
    name: &str,
    range: std::ops::RangeInclusive<u64>,
    what: &str,
) -> PyResult<usize> {
    let want = format!(
        "a whole number from {} to {}: {what}",
        range.start(),
        range.end()
    );
    match count(obj, name, *range.start(), what) {
        Ok(Some(n)) if range.contains(&n) => {
            usize::try_from(n).map_err(|_| refuse(name, obj, &want))
        }
        _ => Err(refuse(name, obj, &want)),
    }
}

pub fn ngspice_arg(obj: &Bound<'_, PyAny>) -> PyResult<Option<PathBuf>> {
    path(obj, "ngspice")
}

pub fn element_arg(obj: &Bound<'_, PyAny>) -> PyResult<Option<ContactElement>> {
    let want = "\"pwl\", \"event-ramp\" or \"switch\", how the contact is emitted";
    match text(obj, "element", want)? {
        None => Ok(None),
        Some(name) => name
            .parse::<ContactElement>()
            .map(Some)
            .map_err(|_| refuse("element", obj, want)),
    }
}

pub fn coupling_arg(obj: &Bound<'_, PyAny>) -> PyResult<Option<Coupling>> {
    let want = "\"lock-step\" or \"passes\", how a coil-driven relay is coupled to its circuit";
    match text(obj, "coupling", want)? {
        None => Ok(None),
        Some(name) => name
            .parse::<Coupling>()
            .map(Some)
            .map_err(|_| refuse("coupling", obj, want)),
    }
}

pub fn max_iterations_arg(obj: &Bound<'_, PyAny>) -> PyResult<usize> {
    bounded(
        obj,
        "max_iterations",
        1..=1_000_000,
        "the most coupling passes",
    )
}

pub fn coupling_tolerance_arg(obj: &Bound<'_, PyAny>) -> PyResult<f64> {
    let want = "a time in seconds > 0 (e.g. 1e-7): how far an event may still move";
    match number(obj, "coupling_tolerance", want)? {
        Some(s) if s.is_finite() && s > 0.0 => Ok(s),
        _ => Err(refuse("coupling_tolerance", obj, want)),
    }
}

pub fn life_phases_arg(obj: &Bound<'_, PyAny>) -> PyResult<usize> {
    bounded(
        obj,
        "life_phases",
        2..=1024,
        "switching phases of an AC endurance figure",
    )
}

pub fn phases_arg(obj: &Bound<'_, PyAny>) -> PyResult<usize> {
    bounded(
        obj,
        "phases",
        2..=1024,
        "switching phases of an AC endurance figure",
    )
}

pub fn no_life_arg(obj: &Bound<'_, PyAny>) -> PyResult<bool> {
    flag(obj, "no_life")
}

pub fn no_spiceinit_arg(obj: &Bound<'_, PyAny>) -> PyResult<bool> {
    flag(obj, "no_spiceinit")
}

pub fn envelope_arg(obj: &Bound<'_, PyAny>) -> PyResult<bool> {
    flag(obj, "envelope")
}

pub fn envelope_samples_arg(obj: &Bound<'_, PyAny>) -> PyResult<usize> {
    bounded(obj, "samples", 1..=1_000_000_000, "relays drawn")
}

pub fn envelope_seed_arg(obj: &Bound<'_, PyAny>) -> PyResult<u64> {
    Ok(count(obj, "seed", 0, "the seed of the draw")?.unwrap_or(1))
}
