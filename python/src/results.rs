//! What `run`, `sweep` and `fit` return: frozen objects of plain Python
//! values (dicts, lists, str, numpy arrays) that pickle by their fields,
//! compare equal field by field (arrays by value) and say in their repr
//! what they hold.

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};

/// Whether `a` and `b` hold the same values: dicts by key, lists and
/// tuples item by item, numpy arrays by dtype, shape and value (where
/// `==` on a dict of arrays would raise).
pub fn same(a: &Bound<'_, PyAny>, b: &Bound<'_, PyAny>) -> PyResult<bool> {
    let py = a.py();
    let ndarray = py.import("numpy")?.getattr("ndarray")?;
    if a.is_instance(&ndarray)? || b.is_instance(&ndarray)? {
        if !(a.is_instance(&ndarray)? && b.is_instance(&ndarray)?) {
            return Ok(false);
        }
        let np = py.import("numpy")?;
        return Ok(a.getattr("dtype")?.eq(b.getattr("dtype")?)?
            && np.call_method1("array_equal", (a, b))?.extract::<bool>()?);
    }
    if let (Ok(x), Ok(y)) = (a.cast::<PyDict>(), b.cast::<PyDict>()) {
        if x.len() != y.len() {
            return Ok(false);
        }
        for (key, value) in x.iter() {
            match y.get_item(&key)? {
                Some(other) if same(&value, &other)? => {}
                _ => return Ok(false),
            }
        }
        return Ok(true);
    }
    if let (Ok(x), Ok(y)) = (a.cast::<PyList>(), b.cast::<PyList>()) {
        if x.len() != y.len() {
            return Ok(false);
        }
        for (p, q) in x.iter().zip(y.iter()) {
            if !same(&p, &q)? {
                return Ok(false);
            }
        }
        return Ok(true);
    }
    a.eq(b)
}

/// `None` for `None`, else the object.
fn opt<'py, T>(py: Python<'py>, value: &Option<Py<T>>) -> Bound<'py, PyAny> {
    match value {
        Some(v) => v.bind(py).clone().into_any(),
        None => py.None().into_bound(py),
    }
}

/// What ``run`` returns: the report, the waveforms and what
/// ngspice ran and said.
#[pyclass(module = "chatterspice", frozen)]
pub struct Run {
    /// The JSON of `chatterspice run --format json`, as a dict.
    #[pyo3(get)]
    pub report: Py<PyAny>,
    /// The bounced run's vectors by name, as in its raw file (`time`,
    /// `v(in)`, ...): float64 arrays of one length.
    #[pyo3(get)]
    pub waveforms: Py<PyDict>,
    /// The ideal-contact run's vectors, or None without that run.
    #[pyo3(get)]
    pub ideal_waveforms: Option<Py<PyDict>>,
    /// The deck ngspice ran: the netlist with the contact included.
    #[pyo3(get)]
    pub deck: String,
    /// The contact include (`contact.inc`) that was run.
    #[pyo3(get)]
    pub include: String,
    /// ngspice's output (stdout and stderr) of the bounced run; for a
    /// coil-driven relay, of its last pass.
    #[pyo3(get)]
    pub log: String,
    /// ngspice's output of the ideal-contact run, or None.
    #[pyo3(get)]
    pub ideal_log: Option<String>,
    /// With `keep_workdir=True`: the bounced run's work directory (deck,
    /// includes, raw file), left in place; else None.
    #[pyo3(get)]
    pub workdir: Option<String>,
    /// With `keep_workdir=True`: the raw file ngspice wrote in
    /// `workdir`, readable with `read_raw`; else None.
    #[pyo3(get)]
    pub raw_path: Option<String>,
    /// With `keep_workdir=True`: the ideal-contact run's work directory.
    #[pyo3(get)]
    pub ideal_workdir: Option<String>,
}

#[pymethods]
impl Run {
    /// A run from its fields, as pickle rebuilds it.
    #[new]
    #[pyo3(signature = (report, waveforms, ideal_waveforms, deck, include, log, ideal_log,
                        workdir, raw_path, ideal_workdir))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        report: Py<PyAny>,
        waveforms: Py<PyDict>,
        ideal_waveforms: Option<Py<PyDict>>,
        deck: String,
        include: String,
        log: String,
        ideal_log: Option<String>,
        workdir: Option<String>,
        raw_path: Option<String>,
        ideal_workdir: Option<String>,
    ) -> Run {
        Run {
            report,
            waveforms,
            ideal_waveforms,
            deck,
            include,
            log,
            ideal_log,
            workdir,
            raw_path,
            ideal_workdir,
        }
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let r = slf.get();
        let fields = (
            r.report.bind(py),
            r.waveforms.bind(py),
            opt(py, &r.ideal_waveforms),
            &r.deck,
            &r.include,
            &r.log,
            &r.ideal_log,
            &r.workdir,
            &r.raw_path,
            &r.ideal_workdir,
        )
            .into_pyobject(py)?;
        PyTuple::new(py, [slf.get_type().into_any(), fields.into_any()])
    }

    fn __eq__(slf: &Bound<'_, Self>, other: &Bound<'_, PyAny>) -> PyResult<bool> {
        let Ok(other) = other.cast::<Run>() else {
            return Ok(false);
        };
        let (a, b) = (slf.get(), other.get());
        let py = slf.py();
        Ok(same(a.report.bind(py), b.report.bind(py))?
            && same(a.waveforms.bind(py), b.waveforms.bind(py))?
            && same(&opt(py, &a.ideal_waveforms), &opt(py, &b.ideal_waveforms))?
            && (&a.deck, &a.include, &a.log, &a.ideal_log)
                == (&b.deck, &b.include, &b.log, &b.ideal_log)
            && (&a.workdir, &a.raw_path, &a.ideal_workdir)
                == (&b.workdir, &b.raw_path, &b.ideal_workdir))
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let report = self.report.bind(py);
        let bounce = report.get_item("bounce")?;
        let mut parts = vec![format!(
            "{} bounces ({})",
            bounce.get_item("bounce_count")?,
            bounce.get_item("outcome")?
        )];
        for probe in report.get_item("probes")?.try_iter()? {
            let probe = probe?;
            parts.push(format!(
                "{}: {} edges",
                probe.get_item("signal")?,
                probe.get_item("edges")?
            ));
        }
        let waveforms = self.waveforms.bind(py);
        let names: Vec<String> = waveforms.keys().extract()?;
        let points = match waveforms.get_item("time")? {
            Some(t) => t.len()?,
            None => 0,
        };
        Ok(format!(
            "<chatterspice.Run {}; {points} points of {}>",
            parts.join(", "),
            names.join(", ")
        ))
    }
}

/// What `sweep` returns: the summary and one row per sample.
#[pyclass(module = "chatterspice", frozen)]
pub struct Sweep {
    /// `summary.json` of `chatterspice sweep`, as a dict.
    #[pyo3(get)]
    pub summary: Py<PyAny>,
    /// `sweep.csv`, one dict per sample in index order: numbers as int or
    /// float, empty cells as None, the rest as str. A list; with `out=`,
    /// a SweepRows that reads them from the file when asked.
    #[pyo3(get)]
    pub rows: Py<PyAny>,
    /// `sweep.csv` as text, byte for byte the file the command writes;
    /// None with `out=` (the file is in `out`).
    #[pyo3(get)]
    pub csv: Option<String>,
    /// With `out=`: the directory the sweep's files were written to.
    #[pyo3(get)]
    pub out: Option<String>,
}

#[pymethods]
impl Sweep {
    /// A sweep from its fields, as pickle rebuilds it.
    #[new]
    #[pyo3(signature = (summary, rows, csv, out=None))]
    fn new(summary: Py<PyAny>, rows: Py<PyAny>, csv: Option<String>, out: Option<String>) -> Sweep {
        Sweep {
            summary,
            rows,
            csv,
            out,
        }
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let s = slf.get();
        let fields = (s.summary.bind(py), s.rows.bind(py), &s.csv, &s.out).into_pyobject(py)?;
        PyTuple::new(py, [slf.get_type().into_any(), fields.into_any()])
    }

    fn __eq__(slf: &Bound<'_, Self>, other: &Bound<'_, PyAny>) -> PyResult<bool> {
        let Ok(other) = other.cast::<Sweep>() else {
            return Ok(false);
        };
        let (a, b) = (slf.get(), other.get());
        let py = slf.py();
        Ok((&a.csv, &a.out) == (&b.csv, &b.out)
            && same(a.summary.bind(py), b.summary.bind(py))?
            && same(a.rows.bind(py), b.rows.bind(py))?)
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let summary = self.summary.bind(py);
        let keys: Vec<String> = summary.get_item("keys")?.extract()?;
        let written = match &self.out {
            Some(dir) => format!(" (written to {dir})"),
            None => String::new(),
        };
        Ok(format!(
            "<chatterspice.Sweep: {} samples of {}; {} failing a limit, {} errors{written}>",
            self.rows.bind(py).len()?,
            if keys.is_empty() {
                "no keys".to_owned()
            } else {
                keys.join(", ")
            },
            summary.get_item("failing")?,
            summary.get_item("errors")?
        ))
    }
}

/// What `fit` returns: the report and the fitted scenario.
#[pyclass(module = "chatterspice", frozen)]
pub struct Fit {
    /// The JSON of `chatterspice fit --format json`, as a dict.
    #[pyo3(get)]
    pub report: Py<PyAny>,
    /// The fitted scenario as TOML, with its `[provenance]` (what `fit -o
    /// FITTED.toml` writes; a netlist path in it is absolute).
    #[pyo3(get)]
    pub scenario: String,
}

#[pymethods]
impl Fit {
    /// A fit from its fields, as pickle rebuilds it.
    #[new]
    fn new(report: Py<PyAny>, scenario: String) -> Fit {
        Fit { report, scenario }
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let f = slf.get();
        let fields = (f.report.bind(py), &f.scenario).into_pyobject(py)?;
        PyTuple::new(py, [slf.get_type().into_any(), fields.into_any()])
    }

    fn __eq__(slf: &Bound<'_, Self>, other: &Bound<'_, PyAny>) -> PyResult<bool> {
        let Ok(other) = other.cast::<Fit>() else {
            return Ok(false);
        };
        let (a, b) = (slf.get(), other.get());
        Ok(a.scenario == b.scenario && same(a.report.bind(slf.py()), b.report.bind(slf.py()))?)
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let mut shown = Vec::new();
        for p in self.report.bind(py).get_item("parameters")?.try_iter()? {
            let p = p?;
            let value: f64 = p.get_item("value")?.extract()?;
            let sigma: Option<f64> = p.get_item("sigma")?.extract().ok().flatten();
            shown.push(match sigma {
                Some(s) => format!("{} = {value:.6} ± {s:.2e}", p.get_item("key")?),
                None => format!("{} = {value:.6}", p.get_item("key")?),
            });
        }
        Ok(format!("<chatterspice.Fit {}>", shown.join(", ")))
    }
}
