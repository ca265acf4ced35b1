//! Tests of `teach_file.rs` and `teach_json.rs`.

use super::*;
use crate::pendant::teach::TaughtPose;
use crate::protocol::ArmSystem;
use proptest::prelude::*;

const H: &str = "\u{feff}name,x_mm,y_mm,z_mm,r_deg,arm,work,tool\r\n";

fn sample() -> TeachList {
    let mut l = TeachList::new();
    let p = |pose, arm, work, tool| TaughtPose {
        pose,
        arm,
        work,
        tool,
    };
    l.record(
        "P1",
        p([300_000, -150_000, 20_000, 45_000], ArmSystem::Right, 0, 0),
    )
    .unwrap();
    l.record(
        "pick, left",
        p([12_345, -500, 0, -90_000], ArmSystem::Left, 1, 2),
    )
    .unwrap();
    l.record(
        "say \"hi\"",
        p(
            [i32::MIN, i32::MAX, -1, 1],
            ArmSystem::Undetermined,
            31,
            127,
        ),
    )
    .unwrap();
    l.record("Überführung 位置", p([0; 4], ArmSystem::Right, 3, 4))
        .unwrap();
    l
}

#[test]
fn csv_is_written_with_3_decimals_and_rfc_4180_quotes() {
    assert_eq!(
        sample().to_csv(),
        "\u{feff}name,x_mm,y_mm,z_mm,r_deg,arm,work,tool\r\n\
         P1,300.000,-150.000,20.000,45.000,right,0,0\r\n\
         \"pick, left\",12.345,-0.500,0.000,-90.000,left,1,2\r\n\
         \"say \"\"hi\"\"\",-2147483.648,2147483.647,-0.001,0.001,undetermined,31,127\r\n\
         Überführung 位置,0.000,0.000,0.000,0.000,right,3,4\r\n"
    );
    assert_eq!(TeachList::new().to_csv(), H);
}

#[test]
fn csv_and_json_round_trip_exactly() {
    let l = sample();
    assert_eq!(TeachList::from_csv(&l.to_csv()), Ok(l.clone()));
    assert_eq!(TeachList::from_json(&l.to_json()), Ok(l.clone()));
    assert_eq!(TeachList::from_csv(H), Ok(TeachList::new()));
    let empty = TeachList::new().to_json();
    assert_eq!(
        TeachList::from_json(&empty),
        Ok(TeachList::new()),
        "{empty}"
    );
    assert!(l.to_json().contains("\"pose\": [\n        300000,"));
    assert!(l.to_json().contains("\"arm\": \"undetermined\""));
}

#[test]
fn csv_tolerates_bom_crlf_blank_trailing_lines_spaces_and_short_decimals() {
    let text = "\u{feff}Name, X_mm ,y_mm,z_mm,r_deg,arm,work,tool\r\n\
                \" P1 \", 1.5 ,-.25,+7,0.,RIGHT, 3 ,4\r\n\r\n  \n";
    let l = TeachList::from_csv(text).unwrap();
    let p = l.get(0).unwrap();
    assert_eq!(p.name, "P1");
    assert_eq!(p.pose, [1500, -250, 7000, 0]);
    assert_eq!((p.arm, p.work, p.tool), (ArmSystem::Right, 3, 4));
    assert_eq!(l.len(), 1);
    // A lone CR ends a line too.
    assert_eq!(
        TeachList::from_csv(&H.replace('\n', "\r")).map(|l| l.len()),
        Ok(0)
    );
}

#[test]
fn parse_thou_is_exact() {
    for (t, v) in [
        ("12.345", 12_345),
        ("-0.500", -500),
        ("0.001", 1),
        ("-2147483.648", i32::MIN),
        ("2147483.647", i32::MAX),
        ("000012.3", 12_300),
        ("5", 5_000),
        ("-0", 0),
    ] {
        assert_eq!(parse_milli(t), Ok(v), "{t}");
    }
    for t in [
        "", "-", ".", "1e3", "12,5", "1.2.3", "--1", "0x10", "1 000", "inf", "NaN",
    ] {
        assert_eq!(
            parse_milli(t),
            Err(format!(
                "\"{t}\" is not a number (use a dot, 3 decimals at most)"
            )),
        );
    }
    assert_eq!(
        parse_milli("1.0005"),
        Err("\"1.0005\" has more than 3 decimals (the resolution is 0.001)".into())
    );
    for t in ["2147483.648", "-2147483.649", "99999999999999999999999"] {
        assert!(parse_milli(t).unwrap_err().contains("out of range"), "{t}");
    }
}

/// Loads `text` into a list that already holds points: it must fail with `line` and
/// `field` and leave the list as it was.
fn refused(text: &str, line: usize, field: Option<&str>) -> String {
    let mut l = sample();
    let e = l.load_csv(text.as_bytes()).unwrap_err();
    assert_eq!(l, sample(), "{text:?}");
    assert_eq!((e.line, e.field.as_deref()), (line, field), "{text:?}: {e}");
    e.to_string()
}

#[test]
fn broken_csv_names_line_and_field_and_changes_nothing() {
    let ok = "P1,1.000,2.000,3.000,4.000,right,0,0\n";
    assert_eq!(
        refused(
            &format!("{H}{ok}P2,1,2,\"12,5\",4,left,0,0\n"),
            3,
            Some("z_mm")
        ),
        "line 3, field z_mm: \"12,5\" is not a number (use a dot, 3 decimals at most)"
    );
    assert_eq!(
        refused(&format!("{H}{ok}P2,1,2,3\n"), 3, Some("r_deg")),
        "line 3, field r_deg: missing column: the line has 4 fields, expected 8 \
         (name,x_mm,y_mm,z_mm,r_deg,arm,work,tool)"
    );
    assert!(refused(&format!("{H}a, b,1,2,3,4,right,0,0\n"), 2, None).contains("extra column"));
    refused(&format!("{H}P2,1.0005,2,3,4,left,0,0\n"), 2, Some("x_mm"));
    refused(&format!("{H}P2,1,3000000,3,4,left,0,0\n"), 2, Some("y_mm"));
    assert_eq!(
        refused(&format!("{H}P2,1,2,3,4,elbow,0,0\n"), 2, Some("arm")),
        "line 2, field arm: \"elbow\" is not an arm system (use right, left or undetermined)"
    );
    assert_eq!(
        refused(&format!("{H}P2,1,2,3,4,left,255,0\n"), 2, Some("work")),
        "line 2, field work: work coordinate system \"255\" is out of range (0-254)"
    );
    refused(&format!("{H}P2,1,2,3,4,left,-1,0\n"), 2, Some("work"));
    refused(&format!("{H}P2,1,2,3,4,left,0,256\n"), 2, Some("tool"));
    refused(
        &format!("{H}P2,1,2,3,4,left,0,99999999999\n"),
        2,
        Some("tool"),
    );
    refused(&format!("{H}P2,1,2,3,4,left,0,\n"), 2, Some("tool"));
    assert_eq!(
        refused(&format!("{H}{ok}\n P1 ,1,2,3,4,left,0,0\n"), 3, None),
        "line 3: blank line (blank lines are allowed only at the end of the file)"
    );
    assert_eq!(
        refused(&format!("{H}{ok}{ok}"), 3, Some("name")),
        "line 3, field name: \"P1\" is already used on line 2"
    );
    refused(&format!("{H}{ok}  ,1,2,3,4,left,0,0\n"), 3, Some("name"));
    refused(
        &format!("{H}{}", ok.replace("P1", &"n".repeat(33))),
        2,
        Some("name"),
    );
    refused(&format!("{H}\"a\nb\",1,2,3,4,left,0,0\n"), 2, Some("name"));
    // Quotes.
    assert!(
        refused(
            &format!("{H}{ok}\"P2,1,2,3,4,left,0,0\n{ok}"),
            3,
            Some("name")
        )
        .contains("never closed")
    );
    assert!(
        refused(&format!("{H}P\"2,1,2,3,4,left,0,0\n"), 2, Some("name")).contains("quote inside")
    );
    assert!(
        refused(&format!("{H}\"P2\"x,1,2,3,4,left,0,0\n"), 2, Some("name"))
            .contains("after the closing quote")
    );
    refused(&format!("{H}P2,1,2,3,4,\"left\"\"\",0,0\n"), 2, Some("arm"));
    // Line numbers are counted inside a quoted field that spans lines.
    refused(
        &format!("{H}\"a\r\nb\"x,1,2,3,4,left,0,0\n"),
        3,
        Some("name"),
    );
    refused(
        &format!("{H}\"a\r\nb\",1,2,3,4,left,0,0\n"),
        2,
        Some("name"),
    );
    // Header and emptiness.
    assert_eq!(
        refused("", 1, None),
        "line 1: the file is empty (a teach list starts with the line \
         name,x_mm,y_mm,z_mm,r_deg,arm,work,tool)"
    );
    refused("\u{feff}\n\n", 1, None);
    assert_eq!(
        refused(ok, 1, Some("name")),
        "line 1, field name: the first line must be the header \
         name,x_mm,y_mm,z_mm,r_deg,arm,work,tool (found \"P1,1.000,2.000,3.000,4.000,right,0,0\")"
    );
    refused("name,x_mm,y_mm,z_mm,r_deg,arm,work\n", 1, Some("tool"));
    refused("name,x_mm,y_mm,z_mm,r_deg,arm,work,tool,note\n", 1, None);
    refused("name,x,y_mm,z_mm,r_deg,arm,work,tool\n", 1, Some("x_mm"));
}

#[test]
fn non_utf8_names_the_line_and_field() {
    let mut bytes = format!("{H}P1,1,2,3,4,left,0,0\n\"a,b\",1,").into_bytes();
    bytes.extend_from_slice(b"\xFF,3,4,left,0,0\n");
    let mut l = sample();
    let e = l.load_csv(&bytes).unwrap_err();
    assert_eq!(l, sample());
    assert_eq!((e.line, e.field.as_deref()), (3, Some("y_mm")));
    assert!(e.message.contains("not UTF-8"), "{e}");
    assert!(
        e.message.contains(&format!("offset {}", bytes.len() - 15)),
        "{e}"
    );
    // A binary file is said to be one, not blamed on a field.
    let e = TeachList::from_csv_bytes(b"\xC3").unwrap_err();
    assert_eq!((e.line, e.field.as_deref()), (1, None));
    assert!(e.message.contains("not a teach list"), "{e}");
    let png = b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR";
    let e = TeachList::from_csv_bytes(png).unwrap_err();
    assert_eq!(e.field, None, "{e}");
    assert!(e.message.contains("binary"), "{e}");
    // A BOM in bytes is fine.
    let mut bom = b"\xEF\xBB\xBF".to_vec();
    bom.extend_from_slice(H.trim_start_matches('\u{feff}').as_bytes());
    assert_eq!(TeachList::from_csv_bytes(&bom), Ok(TeachList::new()));
}

#[test]
fn load_replaces_only_on_success() {
    let mut l = sample();
    l.load_csv(format!("{H}Q,1,2,3,4,left,0,0\n").as_bytes())
        .unwrap();
    assert_eq!(l.len(), 1);
    l.load_json(sample().to_json().as_bytes()).unwrap();
    assert_eq!(l, sample());
    assert!(l.load_json(b"{\"points\": [1]}").is_err());
    assert_eq!(l, sample());
}

fn json_refused(text: &str) -> FileError {
    let mut l = sample();
    let e = l.load_json(text.as_bytes()).unwrap_err();
    assert_eq!(l, sample());
    e
}

#[test]
fn broken_json_names_line_and_field() {
    let point = |name: &str, work: i64, line_end: &str| {
        format!(
            "{{\"name\": \"{name}\", \"pose\": [1, 2, 3, 4], \"arm\": \"left\",{line_end}\
             \"work\": {work}, \"tool\": 0}}"
        )
    };
    let e = json_refused(&format!(
        "{{\"points\": [\n{},\n{}\n]}}",
        point("A", 0, ""),
        point("B", 255, "\n")
    ));
    assert_eq!((e.line, e.field.as_deref()), (4, Some("work")), "{e}");
    assert!(e.message.starts_with("255 is out of range (0-254)"), "{e}");
    let e = json_refused(&format!(
        "{{\"points\": [\n{},\n{}\n]}}",
        point("A", 0, ""),
        point(" A ", 0, "")
    ));
    assert_eq!((e.line, e.field.as_deref()), (3, Some("name")), "{e}");
    assert!(e.message.contains("already used by point 1"), "{e}");
    let e = json_refused(
        "{\"points\": [\n{\"name\": \"A\", \"pose\": [1, 2, 3, 3000000000], \"arm\": \"left\", \"work\": 0, \"tool\": 0}]}",
    );
    assert_eq!((e.line, e.field.as_deref()), (2, Some("pose")), "{e}");
    let e = json_refused(
        "{\"points\": [\n{\"name\": \"A\", \"pose\": [1, 2, 3, 4], \"arm\": \"up\", \"work\": 0, \"tool\": 0}]}",
    );
    assert_eq!((e.line, e.field.as_deref()), (2, Some("arm")), "{e}");
    let e =
        json_refused("{\"points\": [\n{\"name\": \"\", \"pose\": [1, 2, 3, 4], \"arm\": \"up\"}]}");
    assert_eq!(e.line, 2, "{e}");
    let e = json_refused("{\"points\": [\n{\"name\": \"A\"}]}");
    assert_eq!((e.line, e.field.as_deref()), (2, None), "{e}");
    assert!(e.message.contains("missing field"), "{e}");
    let e = json_refused("{\n\"points\": [,]}");
    assert_eq!(e.line, 2, "{e}");
    assert!(e.to_string().starts_with("line 2: "), "{e}");
    let e = json_refused("");
    assert_eq!(e.line, 1, "{e}");
    let e = TeachList::from_json_bytes(b"{\"points\": [{\"name\": \"\xFF\"}]}").unwrap_err();
    assert_eq!(e.line, 1, "{e}");
}

#[test]
fn pretty_json_errors_point_at_the_value() {
    let mut l = TeachList::new();
    let at = |x, work, tool| TaughtPose {
        pose: [x, 2, 3, 4],
        arm: ArmSystem::Left,
        work,
        tool,
    };
    l.record("P1", at(1, 0, 0)).unwrap();
    l.record("pick", at(12_345, 31, 127)).unwrap();
    let j = l.to_json();
    let line_of = |needle: &str| 1 + j[..j.find(needle).unwrap()].matches('\n').count();
    for (from, to, field, line) in [
        (
            "\"work\": 31",
            "\"work\": 255",
            Some("work"),
            line_of("\"work\": 31"),
        ),
        (
            "\"tool\": 127",
            "\"tool\": 300",
            Some("tool"),
            line_of("\"tool\": 127"),
        ),
        ("\"pick\"", "\"P1\"", Some("name"), line_of("\"pick\"") - 1),
        ("\"pick\"", "\" \"", Some("name"), line_of("\"pick\"")),
        ("\"pick\"", "5", None, line_of("\"pick\"")),
        ("12345", "1.5", None, line_of("12345")),
        ("12345", "-2147483649", Some("pose"), line_of("12345") + 4),
    ] {
        let e = json_refused(&j.replacen(from, to, 1));
        assert_eq!((e.line, e.field.as_deref()), (line, field), "{to}: {e}");
    }
    assert_eq!(
        json_refused(&j.replacen("\"work\": 31", "\"work\": 255", 1)).to_string(),
        format!(
            "line {}, field work: 255 is out of range (0-254) (column 17)",
            line_of("\"work\": 31")
        )
    );
}

#[test]
fn the_derived_serde_form_checks_too() {
    // What eframe persistence uses: the plain Deserialize of TeachList.
    let l = sample();
    let v: TeachList = serde_json::from_str(&l.to_json()).unwrap();
    assert_eq!(v, l);
    assert_eq!(
        serde_json::from_str::<TeachList>("{}").unwrap(),
        TeachList::new()
    );
    let p = |n: &str, w: u8| {
        format!("{{\"name\":\"{n}\",\"pose\":[0,0,0,0],\"arm\":\"right\",\"work\":{w},\"tool\":0}}")
    };
    let dup = format!("{{\"points\":[{},{}]}}", p("A", 0), p(" A", 0));
    let e = serde_json::from_str::<TeachList>(&dup).unwrap_err();
    assert!(e.to_string().contains("already used by point 1"), "{e}");
    let bad = format!("{{\"points\":[{}]}}", p("A", 255));
    assert!(serde_json::from_str::<TeachList>(&bad).is_err());
    let trimmed = format!("{{\"points\":[{}]}}", p(" A ", 0));
    let t: TeachList = serde_json::from_str(&trimmed).unwrap();
    assert_eq!(t.get(0).map(|p| p.name.as_str()), Some("A"));
}

fn arb_arm() -> impl Strategy<Value = ArmSystem> {
    prop_oneof![
        Just(ArmSystem::Right),
        Just(ArmSystem::Left),
        Just(ArmSystem::Undetermined)
    ]
}

fn arb_list() -> impl Strategy<Value = TeachList> {
    let name = "[a-zA-Z0-9 ,\"'éü位置;\t]{1,32}";
    let point = (name, any::<[i32; 4]>(), arb_arm(), 0u8..=31, 0u8..=127);
    prop::collection::vec(point, 0..12).prop_map(|points| {
        let mut l = TeachList::new();
        for (name, pose, arm, work, tool) in points {
            let name = name.replace('\t', "");
            let at = TaughtPose {
                pose,
                arm,
                work,
                tool,
            };
            // Blank and duplicate names are refused; the rest go in.
            let _ = l.record(&name, at);
        }
        l
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn files_round_trip_exactly(l in arb_list()) {
        prop_assert_eq!(TeachList::from_csv(&l.to_csv()), Ok(l.clone()));
        prop_assert_eq!(TeachList::from_csv_bytes(l.to_csv().as_bytes()), Ok(l.clone()));
        prop_assert_eq!(TeachList::from_json(&l.to_json()), Ok(l.clone()));
    }

    #[test]
    fn positions_parse_back_exactly(v in any::<i32>()) {
        prop_assert_eq!(parse_milli(&Milli(v).to_string()), Ok(v));
    }

    #[test]
    fn csv_never_panics_on_any_text(s in any::<String>()) {
        let _ = TeachList::from_csv(&s);
        let _ = TeachList::from_json(&s);
    }

    #[test]
    fn csv_never_panics_on_any_bytes(b in prop::collection::vec(any::<u8>(), 0..300)) {
        let _ = TeachList::from_csv_bytes(&b);
        let _ = TeachList::from_json_bytes(&b);
    }

    #[test]
    fn csv_like_text_fails_cleanly(body in "[a-z0-9,\"\\.\\-\r\n é]{0,200}") {
        let mut l = sample();
        match l.load_csv(format!("{H}{body}").as_bytes()) {
            Ok(()) => prop_assert_eq!(TeachList::from_csv(&l.to_csv()), Ok(l)),
            Err(e) => {
                prop_assert_eq!(l, sample());
                prop_assert!(e.line >= 1);
                prop_assert!(!e.message.is_empty());
            }
        }
    }
}

#[test]
fn a_json_object_that_is_not_a_teach_list_is_refused_not_read_as_empty() {
    for text in [
        "{}",
        "{\"anything\": 1}",
        "{\"points\": [], \"extra\": true}",
    ] {
        let e = TeachList::from_json_bytes(text.as_bytes());
        assert!(e.is_err(), "{text} read as a list");
    }
    let e = TeachList::from_json_bytes(b"{}").unwrap_err().to_string();
    assert!(
        e.contains("points"),
        "the reason does not say what is missing: {e}"
    );
}

#[test]
fn a_line_of_a_million_commas_is_refused_as_it_is_split() {
    let mut text = String::from(H);
    text.push_str(&",".repeat(1_000_000));
    let e = TeachList::from_csv_bytes(text.as_bytes()).unwrap_err();
    assert_eq!((e.line, e.field.as_deref()), (2, None));
    assert!(e.message.contains("more than 64 fields"), "{e}");
}

#[test]
fn a_file_of_more_points_than_a_list_holds_is_refused_and_a_full_list_refuses_a_record() {
    use crate::pendant::teach::MAX_POINTS;
    let mut text = String::from(H);
    for i in 0..=MAX_POINTS {
        text.push_str(&format!("P{i},1,2,3,4,left,0,0\n"));
    }
    let e = TeachList::from_csv_bytes(text.as_bytes()).unwrap_err();
    assert!(e.message.contains("at most 10000"), "{e}");
    // Exactly the limit loads, and then the list is full.
    let cut = text.rfind("P10000").unwrap();
    let mut full = TeachList::from_csv_bytes(&text.as_bytes()[..cut]).unwrap();
    assert_eq!(full.len(), MAX_POINTS);
    let at = full.get(0).unwrap().taught();
    assert_eq!(
        full.record("ONE MORE", at),
        Err(crate::pendant::teach::TeachError::ListFull)
    );
    let json = full.to_json();
    assert_eq!(TeachList::from_json(&json).map(|l| l.len()), Ok(MAX_POINTS));
}

#[test]
fn rmc_axis_columns_are_optional_filled_from_the_first_and_checked() {
    let text = "name,x_mm,y_mm,z_mm,r_deg,arm,work,tool,axis1_pu,axis2_pu\n\
                A,1,2,3,4,right,0,0,10.5,-2\n\
                B,1,2,3,4,right,0,0,7,\n\
                C,1,2,3,4,right,0,0,,\n";
    let l = TeachList::from_csv(text).unwrap();
    let axes: Vec<Vec<i32>> = l.iter().map(|p| p.axes.clone()).collect();
    assert_eq!(axes, vec![vec![10_500, -2_000], vec![7_000], vec![]]);
    assert_eq!(TeachList::from_csv(&l.to_csv()).unwrap(), l);
    // A list without axes writes the plain header, as before.
    assert!(sample().to_csv().starts_with(H));
    let gap = "name,x_mm,y_mm,z_mm,r_deg,arm,work,tool,axis1_pu,axis2_pu\nA,1,2,3,4,right,0,0,,3\n";
    let e = TeachList::from_csv(gap).unwrap_err();
    assert_eq!(e.field.as_deref(), Some("axis2_pu"), "{e}");
    let bad = "name,x_mm,y_mm,z_mm,r_deg,arm,work,tool,axis1_pu\nA,1,2,3,4,right,0,0,ten\n";
    assert!(
        TeachList::from_csv(bad)
            .unwrap_err()
            .to_string()
            .contains("axis1_pu")
    );
    let short = "name,x_mm,y_mm,z_mm,r_deg,arm,work,tool,axis1_pu\nA,1,2,3,4,right,0,0\n";
    assert!(
        TeachList::from_csv(short)
            .unwrap_err()
            .to_string()
            .contains("missing column")
    );
    let json = r#"{"points":[{"name":"A","pose":[0,0,0,0],"arm":"right","work":0,"tool":0,"axes":[1,2,3,4,5,6,7,8,9]}]}"#;
    assert!(
        TeachList::from_json(json)
            .unwrap_err()
            .to_string()
            .contains("at most 8")
    );
}
