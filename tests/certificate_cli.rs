//! `hypersynth check` (docs/semantics.md §9.4): the certificate of an exported controller
//! checks, with bounds around the value the report states; a file whose payoffs are halved
//! claims a false lower bound and is refused with exit status 1, naming a state, in text and in
//! JSON; a file without a certificate is an error.

use assert_cmd::Command;

const CASE_STUDY: &str = "specs/case-study/map.txt";
const TASKS: [&str; 4] = ["--phi", "(!O U A) & (!O U B)", "--psi", "!O U A"];

fn check(file: &std::path::Path, json: bool) -> std::process::Output {
    let mut command = Command::cargo_bin("hypersynth").unwrap();
    command.arg("check").arg(file);
    if json {
        command.args(["--format", "json"]);
    }
    command.output().unwrap()
}

#[test]
fn check_certifies_the_exported_bounds_and_refuses_a_false_one() {
    let dir = tempfile::tempdir().unwrap();
    let controller = dir.path().join("controller.json");
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .args(TASKS)
        .args([
            "-q",
            "--discount",
            "0.99",
            "--sigma-l",
            "uniform",
            "--format",
            "json",
        ])
        .args(["--certificate", "--export-controller"])
        .arg(&controller)
        .arg(CASE_STUDY)
        .output()
        .unwrap();
    assert!(output.status.success(), "{output:?}");
    let report: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let value = report["initial"]["value"].as_f64().unwrap();
    let value_upper = report["initial"]["value_upper"].as_f64().unwrap();

    let output = check(&controller, false);
    assert!(output.status.success(), "{output:?}");
    let text = String::from_utf8(output.stdout).unwrap();
    assert!(
        text.starts_with("certified: the controller collects at least "),
        "{text}"
    );
    let output = check(&controller, true);
    let verdict: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    assert_eq!(verdict["certified"], true);
    let (lower, upper) = (
        verdict["lower"].as_f64().unwrap(),
        verdict["upper"].as_f64().unwrap(),
    );
    assert!(
        lower <= value_upper + 1e-9 && value <= upper + 1e-9 && upper - lower <= 1e-6,
        "{verdict} against the value [{value}, {value_upper}]"
    );
    assert!(
        text.contains(&format!("at least {lower} from h0")),
        "{text}"
    );

    // Halved payoffs: the controller collects half, below the claimed lower bound.
    let mut file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&controller).unwrap()).unwrap();
    for payoff in file["payoffs"].as_array_mut().unwrap() {
        *payoff = (payoff.as_f64().unwrap() / 2.0).into();
    }
    for bound in file["value"].as_array_mut().unwrap() {
        *bound = (bound.as_f64().unwrap() / 2.0).into();
    }
    let halved = dir.path().join("halved.json");
    std::fs::write(&halved, file.to_string()).unwrap();
    let output = check(&halved, false);
    assert_eq!(output.status.code(), Some(1), "{output:?}");
    let stderr = String::from_utf8(output.stderr).unwrap();
    assert!(
        stderr.contains("halved.json: the lower certificate fails at state `"),
        "{stderr}"
    );
    let output = check(&halved, true);
    assert_eq!(output.status.code(), Some(1), "{output:?}");
    let verdict: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    assert_eq!(verdict["certified"], false);
    assert_eq!(verdict["certificate"], "lower");

    // No certificate.
    file.as_object_mut().unwrap().remove("certificate");
    std::fs::write(&halved, file.to_string()).unwrap();
    let output = check(&halved, false);
    assert_eq!(output.status.code(), Some(1), "{output:?}");
    assert!(
        String::from_utf8(output.stderr)
            .unwrap()
            .contains("has no certificate")
    );
}

/// The implicit engine's controller carries a certificate that `hypersynth check` certifies,
/// over the same states as the explicit engine's and with the same bounds within the
/// precision (the case study, which decides alike on both engines at g = 0.95 with sigma_L
/// random).
#[test]
fn the_implicit_engines_certificate_checks_as_the_explicit_engines() {
    let dir = tempfile::tempdir().unwrap();
    let verdicts: Vec<serde_json::Value> = ["explicit", "implicit"]
        .into_iter()
        .map(|engine| {
            let controller = dir.path().join(format!("{engine}.json"));
            let output = Command::cargo_bin("hypersynth")
                .unwrap()
                .args(TASKS)
                .args(["-q", "--discount", "0.95", "--sigma-l", "random"])
                .args(["--engine", engine, "--certificate", "--export-controller"])
                .arg(&controller)
                .arg(CASE_STUDY)
                .output()
                .unwrap();
            assert!(output.status.success(), "{engine}: {output:?}");
            let output = check(&controller, true);
            assert!(output.status.success(), "{engine}: {output:?}");
            serde_json::from_slice(&output.stdout).unwrap()
        })
        .collect();
    let [explicit, implicit] = &verdicts[..] else {
        unreachable!()
    };
    assert_eq!(implicit["certified"], true);
    for key in ["lower", "upper"] {
        let (a, b) = (
            explicit[key].as_f64().unwrap(),
            implicit[key].as_f64().unwrap(),
        );
        assert!((a - b).abs() <= 2e-6 * a.max(1.0), "{key}: {a} against {b}");
    }
    let keys = |v: &serde_json::Value| {
        let mut keys: Vec<String> = v.as_object().unwrap().keys().cloned().collect();
        keys.sort();
        keys
    };
    assert_eq!(keys(implicit), keys(explicit));
    for (key, value) in explicit.as_object().unwrap() {
        if value.is_u64() {
            assert_eq!(implicit[key], *value, "{key}");
        }
    }
}
