//! Unit tests of the run deck.
#[test]
fn param_values_and_names_are_read_off_top_level_param_cards() {
    let text = "title\n.param cf=8.2n rf = 1k\n+ tau={rf*cf}\n.subckt f a b\n.param cf=1\n\
                .ends\n.param gain={2.5}\n";
    assert_eq!(param_value(text, "cf"), Some(8.2e-9));
    assert_eq!(param_value(text, "RF"), Some(1e3));
    assert_eq!(param_value(text, "gain"), Some(2.5));
    // An expression has no plain value; an unknown name none at all.
    assert_eq!(param_value(text, "tau"), None);
    assert_eq!(param_value(text, "x"), None);
    assert_eq!(
        param_names(".param cf=8.2n rf = 1k tau={rf*cf}"),
        ["cf", "rf", "tau"]
    );
    assert_eq!(param_names(".PARAM CF = 8.2n"), ["cf"]);
    assert_eq!(param_names(".param x='1k*2' y = { x / 2 }"), ["x", "y"]);
    let upper = "t\n.PARAM CF = 4.7u\n";
    assert_eq!(param_value(upper, "cf"), Some(4.7e-6));
}

#[test]
fn params_are_set_at_the_end_and_must_exist() {
    let text = "t\n.param cf=8.2n\nX1 a 0 CONTACT\nC1 a 0 {cf}\n.tran 1u 10m\n.end\n";
    let deck = prepare_deck_with_params(&req(text, &[]), &[("cf", 4.7e-8)]).unwrap();
    let own = deck.text.find(".param cf=8.2n").unwrap();
    let ours = deck.text.find(".param cf=4.7e-8").unwrap();
    assert!(own < ours && ours < deck.text.find(".end").unwrap());
    let err = prepare_deck_with_params(&req(text, &[]), &[("cx", 1.0)]).unwrap_err();
    let msg = err.to_string();
    assert!(
        msg.contains("circuit.params.cx") && msg.contains("defines: cf"),
        "{msg}"
    );
}

#[test]
fn suggested_stop_times_are_rounded_up_to_two_digits() {
    assert_eq!(super::round_up_2(1.4779929920509072e-3), 1.5e-3);
    assert_eq!(super::round_up_2(1.5e-3), 1.5e-3);
    assert_eq!(super::round_up_2(9.91e-3), 1e-2);
    assert_eq!(super::round_up_2(0.02), 0.02);
    for t in [1.234e-9, 7.77e-4, 3.0000001e-2] {
        assert!(super::round_up_2(t) >= t);
    }
}

use super::*;

fn req<'a>(text: &'a str, probes: &'a [&'a str]) -> DeckRequest<'a> {
    DeckRequest {
        netlist_text: text,
        netlist_path: Path::new("/nonexistent/dir/circuit.cir"),
        include_file_name: "contact.inc",
        subckt: "CONTACT",
        coil: None,
        probes,
        chatter_end: 5e-3,
        stop_at_least: 8e-3,
        options: &[],
    }
}

const BASIC: &str = "My circuit\r\nV1 vdd 0 3.3\r\nR1 vdd in 10k\r\n\
    x1 in\r\n+ 0 contact ; the relay\r\n.tran 1u 10m\r\n.end\r\n";

#[test]
fn a_coil_driven_relay_needs_its_coil_instantiated_and_included() {
    let coil_req = |text| DeckRequest {
        coil: Some(("coil.inc", "COIL")),
        ..req(text, &[])
    };
    let err = prepare_deck(&coil_req(BASIC)).unwrap_err();
    assert!(matches!(err, NetlistError::NoCoilInstance { .. }), "{err}");
    assert!(
        err.to_string().contains("X2 coil_plus coil_minus COIL"),
        "{err}"
    );
    let with_coil = BASIC.replace(".tran", "X2 drv 0 coil\r\n.tran");
    let deck = prepare_deck(&coil_req(&with_coil)).unwrap();
    let lines: Vec<&str> = deck.text.lines().collect();
    assert_eq!(&lines[2..4], [".include contact.inc", ".include coil.inc"]);
    assert_eq!(deck.source_line(4), None);
    assert_eq!(deck.source_line(5).map(|(_, l)| l), Some(2));
}

#[test]
fn instances_are_found_by_their_subcircuit() {
    let text = "title\nX2 a b COIL\nx_relay in\n+ 0 contact\nXother a b COILS\n.end\n";
    assert_eq!(instances_of(text, "coil"), ["x2"]);
    assert_eq!(instances_of(text, "CONTACT"), ["x_relay"]);
    assert!(instances_of(text, "NONE").is_empty());
    // The terminals, across a continuation line.
    assert_eq!(
        instance_nodes_of(text, "CONTACT"),
        [("in".to_owned(), "0".to_owned())]
    );
    assert_eq!(
        instance_nodes_of(text, "coil"),
        [("a".to_owned(), "b".to_owned())]
    );
}

#[test]
fn basic_deck() {
    let deck = prepare_deck(&req(BASIC, &["v(in)"])).unwrap();
    assert_eq!(
        deck.text,
        "My circuit\n* chatterspice run deck for /nonexistent/dir/circuit.cir; that file is \
         not modified\n.include contact.inc\nV1 vdd 0 3.3\nR1 vdd in 10k\nx1 in\n+ 0 contact \
         ; the relay\n.tran 1u 10m\n.end\n"
    );
    assert!(deck.warnings.is_empty(), "{:?}", deck.warnings);
    assert_eq!(deck.tran.tstop, 10e-3);
    assert_eq!(deck.tran.line, 6);
    assert_eq!(deck.tran.effective_max_step(), 1e-6);
}

#[test]
fn instance_detection() {
    assert!(instantiates("X1 a b CONTACT", "contact"));
    assert!(instantiates("xk1 a b Contact r = 1 w=2", "CONTACT"));
    assert!(instantiates("X1 a b CONTACT params: r=1", "CONTACT"));
    assert!(!instantiates("X1 a b CONTACTS", "CONTACT"));
    assert!(!instantiates("R1 a CONTACT 1k", "CONTACT"));
    assert!(!instantiates("X1 CONTACT b OTHER", "CONTACT"));
}

#[test]
fn comments_are_stripped() {
    assert_eq!(strip_comment("R1 a b 1k ; note"), "R1 a b 1k ");
    assert_eq!(strip_comment("R1 a b 1k $ note"), "R1 a b 1k ");
    assert_eq!(strip_comment("R1 a$b c 1k"), "R1 a$b c 1k");
    assert_eq!(strip_comment("* X1 a b CONTACT"), "");
}

#[test]
fn missing_instance_names_the_file_and_the_line_to_add() {
    let text = "t\nR1 a 0 1k\n* X1 a 0 CONTACT\n.tran 1u 10m\n.end\n";
    let e = prepare_deck(&req(text, &[])).unwrap_err();
    assert!(matches!(e, NetlistError::NoContactInstance { .. }));
    let msg = e.to_string();
    assert!(msg.starts_with("/nonexistent/dir/circuit.cir: "), "{msg}");
    assert!(msg.contains("`X1 a b CONTACT`"), "{msg}");
}

#[test]
fn own_subckt_of_that_name_is_an_error() {
    let text = "t\nX1 a 0 CONTACT\n.SUBCKT contact a b\nR1 a b 1\n.ends\n.tran 1u 10m\n";
    let e = prepare_deck(&req(text, &[])).unwrap_err();
    assert!(
        matches!(e, NetlistError::SubcktConflict { line: 3, .. }),
        "{e}"
    );
}

#[test]
fn tran_checks() {
    let deck = |tran: &str| {
        let text = format!("t\nX1 a 0 CONTACT\n{tran}\n.end\n");
        prepare_deck(&req(&text, &[]))
    };
    let e = deck("* none").unwrap_err();
    assert!(
        e.to_string().contains("add a line such as `.tran 1u 8e-3`"),
        "{e}"
    );
    let e = deck(".tran 1u 4m").unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, NetlistError::TranTooShort { line: 3, .. }));
    assert!(
        msg.contains("at least 8e-3 s, e.g. `.tran 1e-6 8e-3`"),
        "{msg}"
    );
    let d = deck(".TRAN 1u 6ms").unwrap();
    assert!(matches!(d.warnings[..], [DeckWarning::StopShort { .. }]));
    // A suggestion keeps the user's step, TMAX and UIC.
    let e = deck(".tran 1e-7 4m 0 2u uic").unwrap_err();
    assert!(
        e.to_string().contains("e.g. `.tran 1e-7 8e-3 0 2e-6 uic`"),
        "{e}"
    );
    let d = deck(".tran 1e-7 6m 0 2u UIC").unwrap();
    assert!(
        d.warnings[0]
            .to_string()
            .contains("use `.tran 1e-7 8e-3 0 2e-6 uic`"),
        "{}",
        d.warnings[0]
    );
    let d = deck(".tran 1u\n+ 10m 0 5u UIC").unwrap();
    assert_eq!(d.tran.tmax, Some(5e-6));
    assert!(d.tran.uic);
    let e = deck(".tran 1u {tstop}").unwrap_err();
    assert!(e.to_string().contains("`{tstop}` is not a number"), "{e}");
    let e = deck(".tran 1u 10m\n.tran 1u 20m").unwrap_err();
    assert!(matches!(
        e,
        NetlistError::TwoTran {
            first: 3,
            second: 4,
            ..
        }
    ));
    assert!(deck(".tran 1u").is_err());
    assert!(deck(".tran 0 10m").is_err());
}

#[test]
fn control_blocks_are_left_out() {
    let text = "t\nX1 a 0 CONTACT\n.control\ntran 1u 10m\nrun\n.endc\n.end\n";
    let e = prepare_deck(&req(text, &[])).unwrap_err();
    assert!(
        e.to_string()
            .contains("outside the `.control` block at line 3"),
        "{e}"
    );
    let text = "t\nX1 a 0 CONTACT\n.tran 1u 10m\n.control\nrun\nquit\n.endc\n";
    let d = prepare_deck(&req(text, &[])).unwrap();
    assert!(!d.text.contains("quit"), "{}", d.text);
    assert!(matches!(
        d.warnings[..],
        [DeckWarning::ControlRemoved {
            first: 4,
            last: 7,
            ..
        }]
    ));
    let text = "t\nX1 a 0 CONTACT\n.tran 1u 10m\n.control\nrun\n";
    assert!(matches!(
        prepare_deck(&req(text, &[])),
        Err(NetlistError::UnclosedControl { line: 4, .. })
    ));
}

#[test]
fn end_is_last_and_saves_follow_user_saves() {
    let text = "t\nX1 a 0 CONTACT\n.tran 1u 10m\n.save v(a)\n.END\nR9 x y 1\n";
    let d = prepare_deck(&req(text, &["v(in)", "V(a,0)", "i(V1)"])).unwrap();
    assert!(
        d.text
            .ends_with(".save v(a)\n* chatterspice: the probes\n.save v(in) v(a) i(V1)\n.end\n"),
        "{}",
        d.text
    );
    assert!(!d.text.contains("R9"));
    assert!(matches!(
        d.warnings[..],
        [DeckWarning::IgnoredAfterEnd { line: 6, .. }]
    ));
    // Without `.save` ngspice saves everything: nothing to add.
    let d = prepare_deck(&req(BASIC, &["v(in)"])).unwrap();
    assert!(!d.text.contains(".save"));
}

#[test]
fn probes_must_be_vectors() {
    assert_eq!(save_names("v(a,b)").unwrap(), ["v(a)", "v(b)"]);
    assert_eq!(save_names(" I(Vdd) ").unwrap(), ["i(Vdd)"]);
    for bad in ["v(in", "in", "v()", "i(a,b)", "p(x)", "v(a b)"] {
        let e = save_names(bad).unwrap_err();
        assert!(e.to_string().contains("`v(node)`"), "{e}");
    }
}

#[test]
fn title_that_is_a_card_is_reported() {
    let text = ".include x.lib\nX1 a 0 CONTACT\n.tran 1u 10m\n";
    let d = prepare_deck(&req(text, &[])).unwrap();
    assert!(matches!(d.warnings[..], [DeckWarning::TitleIsCard { .. }]));
    assert!(d.warnings[0].to_string().contains("line 1"));
}
