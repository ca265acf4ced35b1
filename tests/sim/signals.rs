//! The simulator's signals as a third-party host sees them (PROTOCOL.md 3.34-3.43): the
//! real `xsel-sim` binary over TCP, the exact example frames of 3.50 (20BH-24DH) sent as
//! raw bytes and their replies checked byte for byte, inputs switched on its console
//! (stdin); refusals, and the I/O interlock with 238H's cancel.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{Receiver, channel};
use std::time::{Duration, Instant};

use crate::wait::{LONG, PROCESS};
use crate::wire::{frame, sc};

/// `xsel-sim --tcp` with its console on a pipe, and a host on its line (the programs
/// tests use it too).
pub(crate) struct Sim {
    child: Child,
    console: ChildStdin,
    out: Receiver<String>,
    stream: TcpStream,
}

impl Sim {
    fn start() -> Sim {
        Sim::with(&[])
    }

    /// With these command-line flags.
    pub(crate) fn with(flags: &[&str]) -> Sim {
        let mut child = Command::new(env!("CARGO_BIN_EXE_xsel-sim"))
            .args(["--tcp", "127.0.0.1:0", "--quiet"])
            .args(flags)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("xsel-sim starts");
        let console = child.stdin.take().expect("stdin");
        let stdout = BufReader::new(child.stdout.take().expect("stdout"));
        let (tx, out) = channel();
        std::thread::spawn(move || {
            for line in stdout.lines() {
                let Ok(line) = line else { break };
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        let addr: std::net::SocketAddr = out
            .recv_timeout(PROCESS)
            .expect("the address on stdout")
            .trim()
            .parse()
            .expect("an address");
        let stream = TcpStream::connect(addr).expect("connect");
        stream
            .set_read_timeout(Some(Duration::from_millis(20)))
            .expect("read timeout");
        stream.set_nodelay(true).expect("no delay");
        Sim {
            child,
            console,
            out,
            stream,
        }
    }

    /// Types `line` on the console and waits for its answer (a line holding `want`).
    pub(crate) fn type_line(&mut self, line: &str, want: &str) {
        writeln!(self.console, "{line}").expect("console");
        let deadline = Instant::now() + PROCESS;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.out.recv_timeout(left) {
                Ok(got) if got.contains(want) => return,
                Ok(_) => {}
                Err(_) => panic!("`{line}`: no `{want}` on stdout"),
            }
        }
    }

    /// Sends `text` and CR LF as they are (its SC included); the reply without CR LF.
    pub(crate) fn exact(&mut self, text: &str) -> String {
        self.stream
            .write_all(format!("{text}\r\n").as_bytes())
            .unwrap();
        self.reply(text)
    }

    /// Sends `body` with its SC computed; the reply without CR LF, its SC checked.
    pub(crate) fn ask(&mut self, body: &str) -> String {
        self.stream.write_all(&frame(body)).unwrap();
        let r = self.reply(body);
        let (payload, got) = r.split_at(r.len() - 2);
        assert_eq!(got, sc(payload), "reply SC of {r}");
        r
    }

    fn reply(&mut self, to: &str) -> String {
        let deadline = Instant::now() + LONG;
        let mut got = Vec::new();
        let mut buf = [0u8; 4096];
        while !got.ends_with(b"\r\n") {
            assert!(Instant::now() < deadline, "no reply to {to}");
            if let Ok(n) = self.stream.read(&mut buf) {
                got.extend_from_slice(&buf[..n]);
            }
        }
        String::from_utf8(got).unwrap().trim_end().to_owned()
    }

    /// 215H status byte 2 (PROTOCOL.md 3.4: characters 16-17).
    pub(crate) fn status_byte_2(&mut self) -> u8 {
        let r = self.ask("!99215");
        u8::from_str_radix(&r[15..17], 16).unwrap()
    }
}

impl Drop for Sim {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// `&` with `code`, its SC.
pub(crate) fn err(code: &str) -> String {
    let body = format!("&99{code}");
    format!("{body}{}", sc(&body))
}

/// `body` and its SC.
pub(crate) fn with_sc(body: &str) -> String {
    format!("{body}{}", sc(body))
}

/// PROTOCOL.md 3.50, 20BH-24DH: every example whose reply the state makes certain.
#[test]
fn the_section_3_50_examples_answer_byte_for_byte() {
    let mut sim = Sim::start();
    // 20BH: inputs 0, 2 and 15 on (set on the console, as a sensor would).
    for n in [0, 2, 15] {
        sim.type_line(&format!("in {n} on"), &format!("input {n} on"));
    }
    assert_eq!(sim.exact("!9920B00000010B8"), "#9920B00000010058087");
    // 24AH output 300 ON, then 20CH outputs 300-307.
    assert_eq!(sim.exact("!9924A012C141"), "#9924A3C");
    assert_eq!(sim.exact("!9920C012C0008D6"), "#9920C012C00080139");
    // 24BH global flag 600 ON, local flag 900 of program 3 OFF; 20DH flags 600-615.
    assert_eq!(sim.exact("!9924B00025819B"), "#9924B3D");
    assert_eq!(sim.exact("!9924B03038409D"), "#9924B3D");
    assert_eq!(sim.exact("!9920D000258001029"), "#9920D00025800100100EC");
    // 24CH integers 200 = 123, 201 = -1; read back with 20EH (its layout inferred).
    assert_eq!(
        sim.exact("!9924C000C8020000007BFFFFFFFF72"),
        "#9924C000C802AB"
    );
    assert_eq!(
        sim.exact("!9920E000C802A7"),
        "#9920E000C8020000007BFFFFFFFF72"
    );
    // 24DH real 300 = 1.5 (plain), read back with 20FH in both encodings.
    assert_eq!(
        sim.exact("!9924D0012C013FF8000000000000DB"),
        "#9924D0012C01A6"
    );
    assert_eq!(
        sim.exact("!9920F0012C01A2"),
        "#9920F0012C013FF8000000000000DB"
    );
    sim.type_line("real-encoding swapped", "word-swapped");
    assert_eq!(
        sim.exact("!9920F0012C01A2"),
        "#9920F0012C01000000003FF80000DB"
    );
    // 210H: the example reads global columns 1-5; the same read of program 1's local
    // columns is answered from their own store.
    sim.type_line("var str 1 = \"HELLO\"", "\"HELLO\"");
    assert_eq!(sim.exact("!9921000001057C"), "#99210000010548454C4C4FBB");
    sim.type_line("var str 1 = \"HELLO\" 1", "\"HELLO\"");
    assert_eq!(sim.ask("!992100100105"), with_sc("#99210010010548454C4C4F"));
}

/// Reads and changes the pages or the simulator's numbering do not allow get `&` A03.
#[test]
fn reads_and_changes_out_of_their_category_are_refused() {
    let mut sim = Sim::start();
    for (what, body) in [
        ("start off the grid", "!9920B00040008"),
        ("inputs running into outputs", "!9920B01280010"),
        ("an input read with 20CH", "!9920C01240008"),
        (
            "more ports than the category (and the buffer)",
            "!9920B00001FC8",
        ),
        ("count 0", "!9920B00000000"),
        ("local flags with program 00", "!9920D0003840008"),
        ("global flags with a program", "!9920D0102580008"),
        ("no program 65", "!9920D4103840008"),
        ("an input changed with 24AH", "!9924A00001"),
        ("a local flag changed with program 00", "!9924B0003841"),
        ("a global flag changed with a program", "!9924B0102581"),
        ("an unknown integer variable", "!9920E0006401"),
        ("integers running past 299", "!9920E0012B02"),
        (
            "an unknown local real (local reals are 100-199)",
            "!9920F010C801",
        ),
        (
            "a write past the last integer",
            "!9924C0012B020000000100000002",
        ),
    ] {
        assert_eq!(sim.ask(body), err("A03"), "{what}: {body}");
    }
    // A refused write changed nothing: integer 299 is still 0.
    assert_eq!(sim.ask("!9920E0012B01"), with_sc("#9920E0012B0100000000"));
    // All 100 global reals in one reply.
    let r = sim.ask("!9920F0012C64");
    assert_eq!(r.len(), 13 + 100 * 16 + 2, "100 reals");
}

/// With the 1024-byte reply buffer (J/K/TT setting) a reply holds 62 reals: 63 are
/// refused, not cut (the simulator's choice: PROTOCOL.md does not say).
#[test]
fn a_read_over_the_reply_buffer_is_refused() {
    let mut sim = Sim::with(&["--reply-buffer", "1024"]);
    let r = sim.ask("!9920F0012C3E");
    assert_eq!(r.len(), 13 + 62 * 16 + 2, "62 reals: {r}");
    assert!(r.len() + 2 <= 1024);
    assert_eq!(sim.ask("!9920F0012C3F"), err("A03"));
}

/// While the I/O interlock is on, 24AH is acknowledged but held; releasing it applies
/// the held changes; 238H with its appended byte bit 0 drops them. Flags are not held.
#[test]
fn the_io_interlock_holds_output_changes_and_238h_cancels_them() {
    let mut sim = Sim::start();
    assert_eq!(sim.status_byte_2() & 0x08, 0);
    sim.type_line("interlock on", "I/O interlock on");
    assert_eq!(sim.status_byte_2() & 0x08, 0x08, "215H byte 2 bit 3");
    // Output 301 ON: acknowledged, held.
    assert_eq!(sim.ask("!9924A012D1"), with_sc("#9924A"));
    assert_eq!(sim.ask("!9920C012C0008"), with_sc("#9920C012C000800"));
    // A flag changes at once.
    assert_eq!(sim.ask("!9924B0002581"), with_sc("#9924B"));
    assert_eq!(sim.ask("!9920D0002580008"), with_sc("#9920D000258000801"));
    sim.type_line("io", "held output changes (oldest first): 301 ON");
    sim.type_line("interlock off", "1 held output changes applied");
    assert_eq!(sim.status_byte_2() & 0x08, 0);
    assert_eq!(sim.ask("!9920C012C0008"), with_sc("#9920C012C000802"));
    // Held again, then dropped by 238H with bit 0 of its appended byte.
    sim.type_line("interlock on", "I/O interlock on");
    assert_eq!(sim.ask("!9924A012E1"), with_sc("#9924A"));
    assert_eq!(sim.ask("!99238FF00"), with_sc("#99238"));
    sim.type_line("io", "held output changes (oldest first): 302 ON");
    assert_eq!(sim.ask("!99238FF01"), with_sc("#99238"));
    sim.type_line("interlock off", "0 held output changes applied");
    assert_eq!(sim.ask("!9920C012C0008"), with_sc("#9920C012C000802"));
}
