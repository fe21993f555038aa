//! The KiCad example project in `kicad/example/`: its schematic is wired as
//! its exported netlist says, that netlist runs in ngspice's batch mode, and
//! through ngspice's shared library (what KiCad's simulator loads) the
//! MCU pin falls at every make and rises after every break at the times
//! the tool's own bounce JSON gives.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Path, PathBuf};

use assert_cmd::Command;
use chatterspice::scenario::Scenario;
use serde_json::Value;

use crate::common::{Sexp, all, atom, head, parse_sexp};

fn project(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("kicad/example")
        .join(name)
}

fn read(name: &str) -> String {
    std::fs::read_to_string(project(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The lists directly under `s` whose head is `name`.
fn children<'a>(s: &'a Sexp, name: &str) -> Vec<&'a Sexp> {
    match s {
        Sexp::List(items) => items.iter().filter(|i| head(i) == Some(name)).collect(),
        Sexp::Atom(_) => Vec::new(),
    }
}

fn child<'a>(s: &'a Sexp, name: &str) -> &'a Sexp {
    children(s, name)
        .into_iter()
        .next()
        .unwrap_or_else(|| panic!("no ({name} ...) in {s:?}"))
}

fn number(s: &Sexp, k: usize) -> f64 {
    atom(s, k).and_then(|a| a.parse().ok()).unwrap()
}

/// A point of the sheet in µm, so that equal coordinates compare equal.
type Point = (i64, i64);

fn point(x: f64, y: f64) -> Point {
    ((x * 1000.0).round() as i64, (y * 1000.0).round() as i64)
}

/// The properties of a symbol (library or placed), by name.
fn properties(s: &Sexp) -> BTreeMap<String, String> {
    children(s, "property")
        .into_iter()
        .map(|p| {
            (
                atom(p, 1).unwrap().to_owned(),
                atom(p, 2).unwrap().to_owned(),
            )
        })
        .collect()
}

/// A library symbol's pins (number → position in its own coordinates, y
/// up) and whether it is a power symbol (its pin names the net).
struct LibSymbol {
    pins: BTreeMap<String, (f64, f64)>,
    power: bool,
    properties: BTreeMap<String, String>,
}

fn lib_symbol(s: &Sexp) -> LibSymbol {
    let mut pins = Vec::new();
    all(s, "pin", &mut pins);
    let pins = pins
        .into_iter()
        .map(|p| {
            let at = child(p, "at");
            let num = atom(child(p, "number"), 1).unwrap().to_owned();
            (num, (number(at, 1), number(at, 2)))
        })
        .collect();
    LibSymbol {
        pins,
        power: !children(s, "power").is_empty(),
        properties: properties(s),
    }
}

/// One placed symbol: its reference, library symbol, properties and where
/// each pin ends on the sheet.
struct Placed {
    reference: String,
    lib_id: String,
    properties: BTreeMap<String, String>,
    pins: BTreeMap<String, Point>,
}

/// What KiCad's netlister works out from the sheet: every placed symbol and
/// the name of the net at each point that anything connects to.
struct Connectivity {
    symbols: Vec<Placed>,
    net_of: HashMap<Point, String>,
}

/// Union-find over sheet points.
fn root(parent: &mut HashMap<Point, Point>, p: Point) -> Point {
    let mut r = p;
    while let Some(&q) = parent.get(&r) {
        if q == r {
            break;
        }
        r = q;
    }
    parent.insert(p, r);
    r
}

fn join(parent: &mut HashMap<Point, Point>, a: Point, b: Point) {
    let (ra, rb) = (root(parent, a), root(parent, b));
    parent.insert(ra, rb);
    parent.entry(rb).or_insert(rb);
}

fn connectivity(sheet: &Sexp) -> Connectivity {
    let library: HashMap<String, LibSymbol> = children(child(sheet, "lib_symbols"), "symbol")
        .into_iter()
        .map(|s| (atom(s, 1).unwrap().to_owned(), lib_symbol(s)))
        .collect();
    let mut parent: HashMap<Point, Point> = HashMap::new();
    let mut names: Vec<(Point, String)> = Vec::new();
    let mut ends: Vec<Point> = Vec::new();
    let mut wires: Vec<(Point, Point)> = Vec::new();
    for w in children(sheet, "wire") {
        let xy = children(child(w, "pts"), "xy");
        assert_eq!(xy.len(), 2);
        let (a, b) = (
            point(number(xy[0], 1), number(xy[0], 2)),
            point(number(xy[1], 1), number(xy[1], 2)),
        );
        join(&mut parent, a, b);
        wires.push((a, b));
        ends.extend([a, b]);
    }
    for l in children(sheet, "label") {
        let at = child(l, "at");
        let p = point(number(at, 1), number(at, 2));
        // KiCad names a net labelled on the root sheet `/LABEL`.
        names.push((p, format!("/{}", atom(l, 1).unwrap())));
        parent.entry(p).or_insert(p);
        ends.push(p);
    }
    let mut symbols = Vec::new();
    for s in children(sheet, "symbol") {
        let lib_id = atom(child(s, "lib_id"), 1).unwrap().to_owned();
        let lib = &library[&lib_id];
        let at = child(s, "at");
        // The example places every symbol unrotated and unmirrored, which
        // keeps this reading simple: a pin is the symbol's origin plus its
        // offset, y flipped (libraries count y up, sheets down).
        assert_eq!(number(at, 3), 0.0, "{lib_id} is rotated");
        assert!(children(s, "mirror").is_empty(), "{lib_id} is mirrored");
        let (x, y) = (number(at, 1), number(at, 2));
        let props = properties(s);
        let pins: BTreeMap<String, Point> = lib
            .pins
            .iter()
            .map(|(n, &(px, py))| (n.clone(), point(x + px, y - py)))
            .collect();
        for &p in pins.values() {
            parent.entry(p).or_insert(p);
            ends.push(p);
            if lib.power {
                names.push((p, props["Value"].clone()));
            }
        }
        if !lib.power {
            symbols.push(Placed {
                reference: props["Reference"].clone(),
                lib_id,
                properties: props,
                pins,
            });
        }
    }
    // Connections are made end to end only: nothing ends inside a wire,
    // where KiCad would need a junction to join it.
    for &p in &ends {
        for &(a, b) in &wires {
            let inside = (a.0 == b.0 && p.0 == a.0 && p.1 > a.1.min(b.1) && p.1 < a.1.max(b.1))
                || (a.1 == b.1 && p.1 == a.1 && p.0 > a.0.min(b.0) && p.0 < a.0.max(b.0));
            assert!(!inside, "{p:?} ends inside the wire {a:?}-{b:?}");
        }
    }
    let mut net_name: HashMap<Point, String> = HashMap::new();
    for (p, name) in names {
        let r = root(&mut parent, p);
        if let Some(other) = net_name.insert(r, name.clone()) {
            assert_eq!(other, name, "two names on one net");
        }
    }
    let points: Vec<Point> = parent.keys().copied().collect();
    let net_of = points
        .into_iter()
        .map(|p| {
            let r = root(&mut parent, p);
            let name = net_name.get(&r).cloned();
            (
                p,
                name.unwrap_or_else(|| panic!("the net at {p:?} has no label")),
            )
        })
        .collect();
    Connectivity { symbols, net_of }
}

/// The SPICE line KiCad writes for a placed symbol: its model's pins in
/// `Sim.Pins` order (else pin 1, 2, ...), then the value or model.
fn spice_line(s: &Placed, nets: &HashMap<Point, String>) -> String {
    let p = &s.properties;
    let order: Vec<String> = match p.get("Sim.Pins") {
        Some(map) => map
            .split_whitespace()
            .map(|pair| pair.split_once('=').unwrap().0.to_owned())
            .collect(),
        None => s.pins.keys().cloned().collect(),
    };
    let nodes: Vec<&str> = order.iter().map(|n| nets[&s.pins[n]].as_str()).collect();
    let nodes = nodes.join(" ");
    match p.get("Sim.Device").map(String::as_str) {
        Some("SUBCKT") => format!("X{} {nodes} {}", s.reference, p["Sim.Name"]),
        Some("V") => {
            assert_eq!(p["Sim.Type"], "DC");
            let dc = p["Sim.Params"].strip_prefix("dc=").unwrap();
            format!("{} {nodes} DC {dc}", s.reference)
        }
        // R and C: the device from the reference, the value as written.
        None => format!("{} {nodes} {}", s.reference, p["Value"]),
        Some(other) => panic!("{}: Sim.Device {other}", s.reference),
    }
}

#[test]
fn the_exported_netlist_is_the_schematic_s_circuit() {
    let sheet = parse_sexp(&read("mcu_input.kicad_sch"));
    assert_eq!(head(&sheet), Some("kicad_sch"));
    // KiCad 7's format, which KiCad 8 opens too.
    assert_eq!(atom(child(&sheet, "version"), 1), Some("20230121"));
    let circuit = connectivity(&sheet);
    let netlist = read("mcu_input.cir");
    let lines: Vec<&str> = netlist.lines().collect();
    assert_eq!(lines.first(), Some(&".title KiCad schematic"));
    assert_eq!(lines.last(), Some(&".end"));

    // Every element, and nothing else, with the nets the wires make.
    let expected: BTreeSet<String> = circuit
        .symbols
        .iter()
        .map(|s| spice_line(s, &circuit.net_of))
        .collect();
    let exported: BTreeSet<String> = lines
        .iter()
        .filter(|l| !l.starts_with('.'))
        .map(|l| l.to_string())
        .collect();
    assert_eq!(exported, expected);

    // The contact's model file is included, and the analysis is the
    // schematic's own text directive.
    let contact = circuit
        .symbols
        .iter()
        .find(|s| s.reference == "K1")
        .unwrap();
    assert_eq!(contact.lib_id, "chatterspice:RelayContact");
    let library = &contact.properties["Sim.Library"];
    assert!(lines.contains(&format!(".include \"{library}\"").as_str()));
    let directives: Vec<&str> = children(&sheet, "text")
        .into_iter()
        .filter_map(|t| atom(t, 1))
        .filter(|t| t.starts_with('.'))
        .collect();
    assert_eq!(directives, [".tran 100n 2m"]);
    assert!(lines.contains(&directives[0]));

    // The symbol carries the fields of the shipped library's contact,
    // and its pins sit where the library puts them.
    let lib = parse_sexp(&std::fs::read_to_string(project("../chatterspice.kicad_sym")).unwrap());
    let shipped = children(&lib, "symbol")
        .into_iter()
        .find(|s| atom(s, 1) == Some("RelayContact"))
        .map(lib_symbol)
        .unwrap();
    let embedded = children(child(&sheet, "lib_symbols"), "symbol")
        .into_iter()
        .find(|s| atom(s, 1) == Some("chatterspice:RelayContact"))
        .map(lib_symbol)
        .unwrap();
    assert_eq!(embedded.pins, shipped.pins);
    for key in ["Sim.Device", "Sim.Library", "Sim.Name", "Sim.Pins"] {
        assert_eq!(embedded.properties[key], shipped.properties[key], "{key}");
        assert_eq!(contact.properties[key], shipped.properties[key], "{key}");
    }

    // The project names the schematic's root sheet, and its symbol
    // library table finds the shipped library.
    let pro: Value = serde_json::from_str(&read("mcu_input.kicad_pro")).unwrap();
    assert_eq!(pro["meta"]["filename"], "mcu_input.kicad_pro");
    assert_eq!(pro["sheets"][0][0].as_str(), atom(child(&sheet, "uuid"), 1));
    let table = parse_sexp(&read("sym-lib-table"));
    let uri = children(&table, "lib")
        .into_iter()
        .find(|l| atom(child(l, "name"), 1) == Some("chatterspice"))
        .and_then(|l| atom(child(l, "uri"), 1))
        .unwrap()
        .replace(
            "${KIPRJMOD}",
            project("").to_str().unwrap().trim_end_matches('/'),
        );
    assert!(Path::new(&uri).is_file(), "{uri}");
}

/// The example directory in a temporary one, with the contact include
/// `chatterspice pwl` writes now for the example's scenario.
fn example_with_fresh_include() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(project("mcu_input.cir"), dir.path().join("mcu_input.cir")).unwrap();
    Command::cargo_bin("chatterspice")
        .unwrap()
        .arg("pwl")
        .arg(project("relay.toml"))
        .arg("-o")
        .arg(dir.path().join("contact.inc"))
        .assert()
        .success();
    dir
}

#[test]
fn the_exported_netlist_runs_in_ngspice_batch_mode() {
    let _ng = ngspice_or_skip!();
    // As committed (its include as `pwl` wrote it), and with a fresh one.
    let committed = tempfile::tempdir().unwrap();
    for name in ["mcu_input.cir", "contact.inc"] {
        std::fs::copy(project(name), committed.path().join(name)).unwrap();
    }
    let fresh = example_with_fresh_include();
    for dir in [committed.path(), fresh.path()] {
        let out = std::process::Command::new("ngspice")
            .current_dir(dir)
            .args(["-b", "-r", "out.raw", "mcu_input.cir"])
            .output()
            .unwrap();
        let log = String::from_utf8_lossy(&out.stdout).into_owned()
            + &String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{log}");
        assert!(!log.to_ascii_lowercase().contains("error"), "{log}");
        let raw = chatterspice::rawfile::RawFile::read(dir.join("out.raw")).unwrap();
        let pin = raw.last_transient().unwrap().real("v(/in)").unwrap();
        // Pulled up before the first make, pulled down at the end.
        assert!(pin[0] > 3.29 && pin[pin.len() - 1].abs() < 1e-3, "{pin:?}");
    }
}

/// ngspice's shared library, loaded the way KiCad loads it.
mod shared {
    use std::ffi::{CStr, c_char, c_int, c_short, c_void};
    use std::sync::Mutex;
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::time::{Duration, Instant};

    use libloading::{Library, Symbol};

    /// `vector_info` of sharedspice.h.
    #[repr(C)]
    struct VectorInfo {
        name: *mut c_char,
        kind: c_int,
        flags: c_short,
        real: *mut f64,
        complex: *mut c_void,
        length: c_int,
    }

    type SendChar = unsafe extern "C" fn(*mut c_char, c_int, *mut c_void) -> c_int;
    type ControlledExit = unsafe extern "C" fn(c_int, bool, bool, c_int, *mut c_void) -> c_int;
    type SendData = unsafe extern "C" fn(*mut c_void, c_int, c_int, *mut c_void) -> c_int;
    type SendInitData = unsafe extern "C" fn(*mut c_void, c_int, *mut c_void) -> c_int;
    type BgThreadRunning = unsafe extern "C" fn(bool, c_int, *mut c_void) -> c_int;
    type Init = unsafe extern "C" fn(
        Option<SendChar>,
        Option<SendChar>,
        Option<ControlledExit>,
        Option<SendData>,
        Option<SendInitData>,
        Option<BgThreadRunning>,
        *mut c_void,
    ) -> c_int;
    type Command = unsafe extern "C" fn(*mut c_char) -> c_int;
    type VecInfo = unsafe extern "C" fn(*mut c_char) -> *mut VectorInfo;

    /// What ngspice printed, for a failing test to show.
    static OUTPUT: Mutex<Vec<String>> = Mutex::new(Vec::new());
    static STARTED: AtomicBool = AtomicBool::new(false);
    static FINISHED: AtomicBool = AtomicBool::new(false);
    static EXITED: AtomicBool = AtomicBool::new(false);

    // The callbacks run on ngspice's threads: no panics, nothing but
    // recording.
    unsafe extern "C" fn send_char(text: *mut c_char, _id: c_int, _user: *mut c_void) -> c_int {
        if !text.is_null() {
            // SAFETY: ngspice passes a NUL-terminated string it keeps
            // alive for the call.
            let line = unsafe { CStr::from_ptr(text) }
                .to_string_lossy()
                .into_owned();
            if let Ok(mut out) = OUTPUT.lock() {
                out.push(line);
            }
        }
        0
    }

    unsafe extern "C" fn controlled_exit(
        _status: c_int,
        _unload: bool,
        _quit: bool,
        _id: c_int,
        _user: *mut c_void,
    ) -> c_int {
        EXITED.store(true, Ordering::SeqCst);
        0
    }

    /// `not_running` is true when the background thread has ended.
    unsafe extern "C" fn thread_running(
        not_running: bool,
        _id: c_int,
        _user: *mut c_void,
    ) -> c_int {
        if not_running {
            FINISHED.store(true, Ordering::SeqCst);
        } else {
            STARTED.store(true, Ordering::SeqCst);
        }
        0
    }

    pub struct Shared {
        lib: Library,
    }

    impl Shared {
        /// libngspice.so.0 loaded and initialised; `None` (with a note)
        /// when it is missing, a panic instead with `REQUIRE_NGSPICE=1`.
        pub fn load() -> Option<Shared> {
            // SAFETY: loading runs libngspice's initialisers, which set
            // up nothing but its own state.
            let lib = match unsafe { Library::new("libngspice.so.0") } {
                Ok(lib) => lib,
                Err(e) if std::env::var("REQUIRE_NGSPICE").as_deref() == Ok("1") => panic!(
                    "REQUIRE_NGSPICE=1 but ngspice's shared library cannot be loaded ({e}): \
                     apt-get install -y libngspice0"
                ),
                Err(e) => {
                    use std::io::Write;
                    let _ = writeln!(
                        std::io::stderr(),
                        "note: skipping a test that needs libngspice.so.0 (set REQUIRE_NGSPICE=1 \
                         to fail instead): {e}"
                    );
                    return None;
                }
            };
            let shared = Shared { lib };
            // SAFETY: the signature of sharedspice.h; the callbacks live
            // as long as the program.
            let rc = unsafe {
                let init: Symbol<Init> = shared.lib.get(b"ngSpice_Init\0").unwrap();
                init(
                    Some(send_char),
                    Some(send_char),
                    Some(controlled_exit),
                    None,
                    None,
                    Some(thread_running),
                    std::ptr::null_mut(),
                )
            };
            assert_eq!(rc, 0, "ngSpice_Init: {}", output());
            Some(shared)
        }

        /// Runs an ngspice command; its return code.
        pub fn command(&self, command: &str) -> c_int {
            let mut text = command.as_bytes().to_vec();
            text.push(0);
            // SAFETY: a NUL-terminated buffer ngspice may read (and, as
            // its prototype allows, write) during the call.
            unsafe {
                let run: Symbol<Command> = self.lib.get(b"ngSpice_Command\0").unwrap();
                run(text.as_mut_ptr().cast())
            }
        }

        /// `bg_run`, then waits for the background thread to end, at most
        /// `limit` (then `bg_halt` and a panic).
        pub fn run(&self, limit: Duration) {
            assert_eq!(self.command("bg_run"), 0, "{}", output());
            let start = Instant::now();
            while !FINISHED.load(Ordering::SeqCst) {
                if start.elapsed() > limit {
                    self.command("bg_halt");
                    panic!(
                        "the run did not end within {limit:?} (started: {}): {}",
                        STARTED.load(Ordering::SeqCst),
                        output()
                    );
                }
                std::thread::sleep(Duration::from_millis(5));
            }
            assert!(STARTED.load(Ordering::SeqCst));
            assert!(
                !EXITED.load(Ordering::SeqCst),
                "ngspice exited: {}",
                output()
            );
        }

        /// A copy of the real vector `name` of the current plot.
        pub fn vector(&self, name: &str) -> Vec<f64> {
            let mut text = name.as_bytes().to_vec();
            text.push(0);
            // SAFETY: ngGet_Vec_Info returns null or a pointer to one
            // vector_info it reuses on the next call, whose `real` holds
            // `length` doubles: copied out at once.
            unsafe {
                let get: Symbol<VecInfo> = self.lib.get(b"ngGet_Vec_Info\0").unwrap();
                let info = get(text.as_mut_ptr().cast());
                assert!(!info.is_null(), "no vector {name}: {}", output());
                let info = &*info;
                assert!(!info.real.is_null(), "{name} is not real");
                std::slice::from_raw_parts(info.real, info.length as usize).to_vec()
            }
        }

        /// Leaves the library loaded: ngspice keeps global state and
        /// threads of its own, so it is never unloaded under them.
        pub fn keep(self) {
            std::mem::forget(self.lib);
        }
    }

    /// ngspice's last lines of output.
    pub fn output() -> String {
        let out = OUTPUT.lock().map(|o| o.clone()).unwrap_or_default();
        out[out.len().saturating_sub(30)..].join("\n")
    }
}

/// A value as SPICE writes it: `10k`, `1n`, `3.3`.
fn spice_number(text: &str) -> f64 {
    let (digits, scale) = match text.chars().last() {
        Some('k') => (&text[..text.len() - 1], 1e3),
        Some('n') => (&text[..text.len() - 1], 1e-9),
        Some('u') => (&text[..text.len() - 1], 1e-6),
        _ => (text, 1.0),
    };
    digits.parse::<f64>().unwrap() * scale
}

/// Times `signal` (sampled at `time`) crosses `level`, linearly
/// interpolated, with whether it was falling.
fn crossings(time: &[f64], signal: &[f64], level: f64) -> Vec<(bool, f64)> {
    let mut out = Vec::new();
    for k in 1..time.len() {
        let (a, b) = (signal[k - 1] - level, signal[k] - level);
        if (a > 0.0) != (b > 0.0) {
            let t = time[k - 1] + (time[k] - time[k - 1]) * a / (a - b);
            out.push((a > 0.0, t));
        }
    }
    out
}

/// Set in the process that runs the shared-library test's body.
const IN_OWN_PROCESS: &str = "CHATTERSPICE_TEST_OWN_PROCESS";

/// ngspice's shared library is one set of globals per process, and the
/// lock-step tests of this binary load and initialise it with callbacks of
/// their own: KiCad's use of it (its own callbacks, a background run) is
/// run in a process of its own, this test binary again with this test
/// alone.
#[test]
fn libngspice_runs_the_example_and_the_pin_follows_the_bounce() {
    if std::env::var_os(IN_OWN_PROCESS).is_some() {
        kicad_uses_the_shared_library();
        return;
    }
    let out = std::process::Command::new(std::env::current_exe().unwrap())
        .args([
            "--exact",
            "kicad_project::libngspice_runs_the_example_and_the_pin_follows_the_bounce",
            "--nocapture",
            "--test-threads=1",
        ])
        .env(IN_OWN_PROCESS, "1")
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // The test ran (a filter that matched nothing would pass too).
    assert!(stdout.contains("1 passed"), "{stdout}");
}

fn kicad_uses_the_shared_library() {
    let Some(ngspice) = shared::Shared::load() else {
        return;
    };
    let dir = example_with_fresh_include();
    let netlist = dir.path().join("mcu_input.cir");
    let path = netlist.to_str().unwrap();
    assert!(!path.contains(char::is_whitespace), "{path}");

    // KiCad's simulator hands libngspice the netlist and runs it; the
    // include is found beside the netlist.
    assert_eq!(
        ngspice.command(&format!("source {path}")),
        0,
        "{}",
        shared::output()
    );
    ngspice.run(std::time::Duration::from_secs(10));
    let time = ngspice.vector("time");
    let pin = ngspice.vector("v(/in)");
    ngspice.keep();
    assert_eq!(time.len(), pin.len());

    // The circuit's own values: VDD, the pull-up and the capacitor.
    let text = std::fs::read_to_string(&netlist).unwrap();
    let value = |name: &str| {
        let line = text.lines().find(|l| l.starts_with(name)).unwrap();
        spice_number(line.split_whitespace().last().unwrap())
    };
    let (vdd, r, c) = (value("V1 "), value("R1 "), value("C1 "));
    let tau = r * c;
    let edge_time = Scenario::load(&project("relay.toml"))
        .unwrap()
        .contact
        .edge_time;

    let out = Command::cargo_bin("chatterspice")
        .unwrap()
        .args(["bounce", "--format", "json"])
        .arg(project("relay.toml"))
        .output()
        .unwrap();
    assert!(out.status.success());
    let bounce: Value = serde_json::from_slice(&out.stdout).unwrap();
    let impacts = bounce["impacts"].as_array().unwrap();

    // At half the supply: the pin falls when the contact makes, and rises
    // τ·ln 2 after it breaks (charging from ~0 V through R1 into C1).
    let rise = tau * 2f64.ln();
    let mut expected = Vec::new();
    for impact in impacts {
        expected.push((true, impact["impact_time"].as_f64().unwrap()));
        if let Some(release) = impact["release_time"].as_f64() {
            expected.push((false, release + rise));
            // Every opening is long enough to show: none within 2× of the
            // time the pin needs, so none is seen or missed by luck.
            let next = impacts.iter().map(|i| i["impact_time"].as_f64().unwrap());
            let open = next.filter(|&t| t > release).fold(f64::INFINITY, f64::min) - release;
            assert!(open > 2.0 * rise, "an opening of {open} s");
        }
    }
    let seen = crossings(&time, &pin, vdd / 2.0);
    assert_eq!(
        seen.len(),
        1 + 2 * bounce["bounce_count"].as_u64().unwrap() as usize
    );
    assert_eq!(seen.len(), expected.len(), "{seen:?}");
    for (&(falls, t), &(want_fall, want)) in seen.iter().zip(&expected) {
        assert_eq!(falls, want_fall, "at {t}");
        // The contact's conductance ramps over one edge time: the pin
        // falls within it of the make (1 nF through a conductance that
        // reaches 1 S within a nanosecond), and stays held until the break's
        // ramp is nearly done. The rise is an exponential of τ = 10 µs,
        // whose 1.65 V crossing ngspice's truncation error (RELTOL 1e-3)
        // may move by ~RELTOL·τ = 10 ns; reading it between points at
        // most 100 ns apart adds h²/(8τ) ≈ 0.1 ns.
        let late = t - want;
        let (early_limit, late_limit) = if falls {
            (1e-9, edge_time + 1e-9)
        } else {
            (1e-3 * tau, edge_time + 1e-3 * tau)
        };
        assert!(
            late >= -early_limit && late <= late_limit,
            "{} edge at {t} s, expected {want} s: {late:e} s off",
            if falls { "falling" } else { "rising" }
        );
    }
}

/// At the MCU pin, the trapezoidal rule rings at the contact's sharp make
/// (C1 across the contact: samples down to −157 mV where the pin
/// discharges from 3.3 V to 16.5 µV). `run` reports the minimum of every
/// sample, and beside it the range without the samples that alternate
/// point to point (a single overshoot that creeps back, tens of mV, stays:
/// it has the shape of a real inrush), with a warning; a `min_value` limit
/// of −50 mV fails on the ringing unless the probe sets
/// `ignore_ringing = true`. With Gear integration in the
/// netlist, as the docs tell KiCad users to set, there is no ringing.
#[test]
fn the_reported_minimum_at_the_pin_is_the_circuit_s() {
    let _ng = ngspice_or_skip!();
    let run = |scenario: &Path| -> Value {
        let out = Command::cargo_bin("chatterspice")
            .unwrap()
            .args(["run", "--format", "json"])
            .arg(scenario)
            .assert()
            .success();
        serde_json::from_slice(&out.get_output().stdout).unwrap()
    };
    let ringing = |v: &Value| {
        v["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .filter_map(Value::as_str)
            .any(|w| w.starts_with("v(/in): ") && w.contains("ring up and down"))
    };
    let report = run(&project("relay.toml"));
    let pin = &report["probes"][0];
    let min = pin["min"].as_f64().unwrap();
    assert!(min < -0.1, "every sample: min {min}");
    let circuit = pin["min_without_ringing"].as_f64().unwrap();
    assert!(
        circuit > min && circuit.abs() < 0.05,
        "without the ringing: {circuit}"
    );
    assert!(ringing(&report), "{}", report["warnings"]);

    // The same circuit with `.options method=gear trtol=1`.
    let dir = tempfile::tempdir().unwrap();
    let netlist = read("mcu_input.cir").replace(
        ".tran 100n 2m",
        ".tran 100n 2m\n.options method=gear trtol=1",
    );
    std::fs::write(dir.path().join("mcu_input.cir"), netlist).unwrap();
    std::fs::copy(project("contact.inc"), dir.path().join("contact.inc")).unwrap();
    let scenario = dir.path().join("relay.toml");
    std::fs::write(
        &scenario,
        read("relay.toml").replace("low = 0.99", "min_value = -0.05\nlow = 0.99"),
    )
    .unwrap();
    let gear = run(&scenario);
    let gear_min = gear["probes"][0]["min"].as_f64().unwrap();
    assert!(gear_min.abs() < 0.01, "min {gear_min}");
    assert!(gear["probes"][0]["min_without_ringing"].is_null());
    assert!(!ringing(&gear), "{}", gear["warnings"]);

    let check = |scenario: &Path| {
        Command::cargo_bin("chatterspice")
            .unwrap()
            .arg("check")
            .arg(scenario)
            .output()
            .unwrap()
            .status
            .code()
    };
    assert_eq!(check(&scenario), Some(0), "Gear: no ringing to fail on");

    // In the netlist as exported, min_value = −50 mV fails on the
    // ringing's −157 mV, and holds with ignore_ringing.
    std::fs::copy(project("mcu_input.cir"), dir.path().join("mcu_input.cir")).unwrap();
    assert_eq!(check(&scenario), Some(1));
    std::fs::write(
        &scenario,
        read("relay.toml").replace(
            "low = 0.99",
            "min_value = -0.05\nignore_ringing = true\nlow = 0.99",
        ),
    )
    .unwrap();
    assert_eq!(check(&scenario), Some(0));
}
