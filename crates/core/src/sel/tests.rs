//! The parser: the demo, every command, conditions, and the errors named by line and
//! column with the rest kept.

use super::*;

fn command(p: &Program, step: usize) -> Command {
    p.steps[step - 1]
        .row
        .as_ref()
        .and_then(|r| r.command.clone())
        .unwrap()
}

#[test]
fn the_demo_parses_and_runs_five_cycles_of_pick_and_place() {
    let parsed = parse(DEMO);
    assert!(parsed.errors.is_empty(), "{:?}", parsed.errors);
    let p = &parsed.programs[0];
    assert_eq!((p.number, p.name.as_str()), (1, "pick and place"));
    assert_eq!(p.steps.len(), 15);
    assert_eq!(command(p, 1), Command::Vel(Value::Literal(200.0)));
    assert_eq!(command(p, 6), Command::MoveP(Value::Literal(1.0)));
    assert_eq!(p.tag(1), Some(4));
    let goto = p.steps[13].row.as_ref().unwrap();
    assert_eq!(
        goto.condition,
        Some(Condition {
            join: Join::Load,
            negated: false,
            number: 900
        })
    );
    assert_eq!(p.steps[12].row.as_ref().unwrap().output, Some(900));
    assert!(p.moves());
    assert_eq!(parsed.runnable().count(), 1);
}

#[test]
fn every_command_and_field_form_reads() {
    let text = "PROGRAM 7 all of it  # comment\n\
                MOVL *12\n\
                BTON 300 307 - \n\
                BTOF 600\n\
                WTON 16 2.5 610\n\
                N17 WTOF 17\n\
                LD 16\n\
                A N601\n\
                O 302 TIMW 1.25\n\
                SUB 201 *1\n\
                CPGE 1 -3 901\n\
                TAG 256\n\
                GOTO 256\n\
                EXIT\n";
    let parsed = parse(text);
    assert!(parsed.errors.is_empty(), "{:?}", parsed.errors);
    let p = &parsed.programs[0];
    assert_eq!(p.name, "all of it");
    assert_eq!(command(p, 1), Command::MoveL(Value::Variable(12)));
    assert_eq!(
        command(p, 2),
        Command::Bits {
            on: true,
            from: 300,
            to: 307
        }
    );
    assert_eq!(
        command(p, 4),
        Command::WaitBit {
            on: true,
            number: 16,
            timeout: Some(Value::Literal(2.5))
        }
    );
    assert_eq!(p.steps[3].row.as_ref().unwrap().output, Some(610));
    assert!(p.steps[4].row.as_ref().unwrap().condition.unwrap().negated);
    let alone = p.steps[5].row.as_ref().unwrap();
    assert_eq!(alone.command, None);
    let and = p.steps[6].row.as_ref().unwrap().condition.unwrap();
    assert_eq!((and.join, and.negated, and.number), (Join::And, true, 601));
    assert_eq!(
        p.steps[7].row.as_ref().unwrap().condition.unwrap().join,
        Join::Or
    );
    assert_eq!(
        command(p, 10),
        Command::Compare {
            op: Compare::Ge,
            var: 1,
            value: Value::Literal(-3.0)
        }
    );
    assert!(!p.moves() || matches!(command(p, 1), Command::MoveL(_)));
}

#[test]
fn errors_name_line_and_column_and_keep_the_rest() {
    let text = "PROGRAM 1 good\n\
                VEL 100\n\
                PROGRAM 2 bad\n\
                VEL 100\n\
                MOVP 1.5\n\
                \x20 JUMP 3\n\
                BTON 16\n\
                GOTO 9\n\
                PROGRAM 3 fine\n\
                EXIT\n\
                PROGRAM 99\n\
                VEL 1\n";
    let parsed = parse(text);
    let said: Vec<String> = parsed.errors.iter().map(|e| e.to_string()).collect();
    assert!(
        said[0].starts_with("line 5, column 6: 1.5: a whole number"),
        "{said:?}"
    );
    assert!(
        said[1].starts_with("line 6, column 3: unknown command JUMP"),
        "{said:?}"
    );
    assert!(
        said[2].starts_with("line 7, column 6: \"16\": an output"),
        "{said:?}"
    );
    assert!(
        said[3].starts_with("line 11, column 9: program number \"99\""),
        "{said:?}"
    );
    assert!(
        said[4].starts_with("line 12, column 1: a step before any PROGRAM"),
        "{said:?}"
    );
    assert_eq!(said[5], "line 8, column 6: GOTO 9: program 2 has no TAG 9");
    let runnable: Vec<u8> = parsed.runnable().map(|p| p.number).collect();
    assert_eq!(runnable, [1, 3]);
    let bad = &parsed.programs[1];
    assert_eq!((bad.steps.len(), bad.errors), (5, 4));
    assert!(bad.steps[1].row.is_none(), "the step is kept, unread");
    assert_eq!(bad.steps[1].text, "MOVP 1.5");
}

#[test]
fn fields_conditions_and_numbers_out_of_bounds_are_refused() {
    for (line, column, words) in [
        ("VEL 100 2", 9, "VEL takes no operand 2"),
        ("TAG 0", 5, "a tag number"),
        ("LET 100 1", 5, "integer variable number"),
        ("LET 1", 7, "LET needs a value"),
        ("1000 EXIT", 1, "a condition"),
        ("A EXIT", 1, "A needs a condition"),
        ("AB 16 EXIT", 1, "block condition"),
        ("BTON 305 302", 10, "does not end a range"),
        ("BTON 599 600", 10, "does not end a range"),
        ("TIMW 1e3", 6, "not a number"),
        ("TIMW inf", 6, "not a number"),
        ("EXIT 1", 6, "EXIT takes no operand 1"),
        ("MOVP 1 - - 300", 12, "too many fields"),
        ("16 ?? 1", 4, "is not a command"),
    ] {
        let parsed = parse(&format!("PROGRAM 1\n{line}\n"));
        let e = &parsed.errors[0];
        assert_eq!((e.line, e.column), (2, column), "{line}: {e}");
        assert!(e.message.contains(words), "{line}: {e}");
        assert_eq!(e.program, Some(1));
    }
    let twice = parse("PROGRAM 1\nPROGRAM 1\nTAG 2\nTAG 2\n");
    assert!(twice.errors[0].message.contains("defined twice"));
}

#[test]
fn errors_are_bounded_and_every_program_is_bounded_in_steps() {
    let many = "X\n".repeat(MAX_ERRORS + 50);
    let parsed = parse(&many);
    assert_eq!((parsed.errors.len(), parsed.unlisted), (MAX_ERRORS, 50));
    let long = format!("PROGRAM 2\n{}", "EXIT\n".repeat(MAX_STEPS + 1));
    let parsed = parse(&long);
    assert_eq!(parsed.programs[0].steps.len(), MAX_STEPS);
    assert_eq!(parsed.runnable().count(), 0);
    assert!(parsed.errors[0].message.contains("more than 9999 steps"));
}
