//! The tests of `fake.rs`: in a file of their own, so that the
//! checkout's test data they name stays out of the module's code.

use super::*;

fn golden(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/raw")
        .join(name)
}

#[test]
fn serves_by_deck_content_and_records_requests() {
    let fake = FakeRunner::default()
        .when_deck_contains(".ac", golden("rc_ac.raw"))
        .fail_when_deck_contains(
            "broken",
            Failure::Netlist {
                line: Some(2),
                text: None,
                reason: "test".into(),
            },
        )
        .time_out_when_deck_contains("forever")
        .otherwise(golden("rc_tran.raw"));
    let ac = fake
        .run(&RunRequest::new("t\n.ac dec 3 10 100k\n"))
        .unwrap();
    assert_eq!(ac.raw.plots[0].name, "AC Analysis");
    let tran = fake.run(&RunRequest::new("t\n.tran 1u 1m\n")).unwrap();
    assert_eq!(tran.raw.plots[0].name, "Transient Analysis");
    assert!(matches!(
        fake.run(&RunRequest::new("broken")),
        Err(SpiceError::Failed { .. })
    ));
    assert!(matches!(
        fake.run(&RunRequest::new("forever")),
        Err(SpiceError::Timeout { .. })
    ));
    assert_eq!(fake.requests().len(), 4);
    assert_eq!(fake.requests()[1].deck, "t\n.tran 1u 1m\n");
}

#[test]
fn killed_file_warnings_pass_through() {
    let out = FakeRunner::serving(golden("killed_binary.raw"))
        .run(&RunRequest::new("x"))
        .unwrap();
    assert_eq!(out.warnings.len(), 1);
}

#[test]
fn runner_is_object_safe_and_shareable() {
    let runner: Box<dyn Runner> = Box::new(FakeRunner::failing(Failure::Aborted));
    std::thread::scope(|s| {
        s.spawn(|| assert!(runner.run(&RunRequest::new("x")).is_err()));
    });
}
