//! Robot model files: the shipped ones load; bad ones are refused naming field and line.

use xsel_pendant::robot::{ModelError, RobotModel};
use xsel_pendant::session::load_model;

const GOOD: &str = include_str!("../../assets/robots/scara-500.toml");

/// Replaces the first line that starts with `prefix` inside section `[section]`.
fn edit(section: &str, prefix: &str, replacement: &str) -> (String, usize) {
    let mut in_section = false;
    let mut out = Vec::new();
    let mut at = 0;
    for (i, line) in GOOD.lines().enumerate() {
        if line.starts_with('[') {
            in_section = line.starts_with(&format!("[{section}]"));
        }
        if in_section && at == 0 && line.starts_with(prefix) {
            out.push(replacement.to_string());
            at = i + 1;
        } else {
            out.push(line.to_string());
        }
    }
    assert!(at > 0, "no `{prefix}` in [{section}]");
    (out.join("\n"), at)
}

fn field_error(text: &str) -> (String, Option<usize>, String) {
    match RobotModel::from_toml_str(text) {
        Err(ModelError::Field {
            field,
            line,
            message,
        }) => (field, line, message),
        other => panic!("expected a field error, got {other:?}"),
    }
}

#[test]
fn shipped_files_load_and_say_they_are_examples() {
    for path in [
        "assets/robots/scara-500.toml",
        "assets/robots/scara-250.toml",
    ] {
        let m = load_model(path).unwrap();
        assert!(m.arm1_mm > 0.0 && m.arm2_mm > 0.0);
        let text = std::fs::read_to_string(path).unwrap();
        assert!(text.contains("EXAMPLES") && text.contains("vendor catalogue"));
    }
    let big = load_model("assets/robots/scara-500.toml").unwrap();
    let small = load_model("assets/robots/scara-250.toml").unwrap();
    assert_eq!(big.arm1_mm + big.arm2_mm, 500.0);
    assert_eq!(small.arm1_mm + small.arm2_mm, 250.0);
    assert_eq!((big.work_table_size, big.tool_table_size), (32, 128));
}

#[test]
fn wrong_type_names_field_and_line() {
    let (text, line) = edit("j2", "max =", "max = \"lots\"");
    let (field, at, message) = field_error(&text);
    assert_eq!(field, "j2.max", "{message}");
    assert_eq!(at, Some(line));
    let shown = RobotModel::from_toml_str(&text).unwrap_err().to_string();
    assert_eq!(
        shown,
        format!(
            "robot model line {line}, field `j2.max`: invalid type: string \"lots\", expected f64"
        )
    );
    assert!(
        shown.contains(&format!("line {line}")) && shown.contains("j2.max"),
        "{shown}"
    );
}

#[test]
fn unknown_field_is_named() {
    let (text, line) = edit("arms", "arm2_mm", "arm2_mmm = 250.0");
    let (field, at, message) = field_error(&text);
    assert!(field.contains("arm2_mmm"), "{field}: {message}");
    assert_eq!(at, Some(line));
}

#[test]
fn missing_field_is_named() {
    let (text, _) = edit("z", "max_accel", "");
    let (field, _, message) = field_error(&text);
    assert!(field.contains("max_accel"), "{field}: {message}");
    assert!(field.starts_with("z"), "{field}: {message}");
}

#[test]
fn bad_values_name_field_and_line() {
    let cases = [
        ("arms", "arm1_mm", "arm1_mm = -250.0", "arms.arm1_mm"),
        ("j1", "max =", "max = -130.0", "j1.max"),
        ("z", "max_speed", "max_speed = 0", "z.max_speed"),
        (
            "arms",
            "singular_band_deg",
            "singular_band_deg = 150",
            "arms.singular_band_deg",
        ),
        ("home", "j2", "j2 = 170.0", "home.j2"),
        ("tables", "tool", "tool = 0", "tables.tool"),
        (
            "defaults",
            "ptp_speed_pct",
            "ptp_speed_pct = 150",
            "defaults.ptp_speed_pct",
        ),
        ("cp", "max_accel_g", "max_accel_g = nan", "cp.max_accel_g"),
    ];
    for (section, prefix, replacement, want) in cases {
        let (text, line) = edit(section, prefix, replacement);
        let (field, at, message) = field_error(&text);
        assert_eq!(field, want, "{replacement}: {message}");
        assert_eq!(at, Some(line), "{replacement}: {message}");
    }
}

#[test]
fn broken_toml_gives_a_line() {
    let (text, line) = edit("j1", "min", "min = = 3");
    let (_, at, _) = field_error(&text);
    assert_eq!(at, Some(line));
}

#[test]
fn a_missing_file_a_fifo_or_an_endless_device_is_refused_with_its_name() {
    let e = load_model("assets/robots/no-such-robot.toml").unwrap_err();
    assert!(
        e.contains("cannot read") && e.contains("no-such-robot.toml"),
        "{e}"
    );
    #[cfg(target_os = "linux")]
    {
        let e = load_model("/dev/zero").unwrap_err();
        assert!(e.contains("/dev/zero is not a regular file"), "{e}");
    }
}
