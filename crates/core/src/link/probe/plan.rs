//! What a probe tries, in which order, and how long that can take.

use std::fmt;
use std::time::Duration;

use super::super::timing::Timing;
use super::error::ProbeError;
use crate::line::{LineSettings, Parity};
use crate::protocol::{Command, ScMode, Station};

/// Baud rates in the order they are tried: those observed in host programs first
/// (115200, 38400, 9600; PROTOCOL.md 1.1), then the rest of the X-SEL family's, then
/// 230400 for serial-to-Ethernet bridges. The same set as `line::STANDARD_BAUDS`
/// `[inferred order]`.
pub const LIKELY_BAUDS: [u32; 6] = [115_200, 38_400, 9_600, 19_200, 57_600, 230_400];

/// Data bits, parity and stop bits of a line (PROTOCOL.md 1.1: I/O parameters 93-95).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Framing {
    /// 7 or 8.
    pub data_bits: u8,
    pub parity: Parity,
    /// 1 or 2.
    pub stop_bits: u8,
}

impl Framing {
    /// 8 data bits, no parity, 1 stop bit: what every observed host uses.
    pub const EIGHT_N_ONE: Framing = Framing::new(8, Parity::None, 1);
    pub const EIGHT_E_ONE: Framing = Framing::new(8, Parity::Even, 1);
    pub const EIGHT_O_ONE: Framing = Framing::new(8, Parity::Odd, 1);
    pub const SEVEN_E_ONE: Framing = Framing::new(7, Parity::Even, 1);
    pub const SEVEN_O_ONE: Framing = Framing::new(7, Parity::Odd, 1);

    pub const fn new(data_bits: u8, parity: Parity, stop_bits: u8) -> Self {
        Self {
            data_bits,
            parity,
            stop_bits,
        }
    }

    /// These settings at `baud`.
    pub const fn at(self, baud: u32) -> LineSettings {
        LineSettings {
            baud,
            data_bits: self.data_bits,
            parity: self.parity,
            stop_bits: self.stop_bits,
        }
    }
}

impl fmt::Display for Framing {
    /// "8N1".
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let parity = match self.parity {
            Parity::None => 'N',
            Parity::Odd => 'O',
            Parity::Even => 'E',
        };
        write!(f, "{}{parity}{}", self.data_bits, self.stop_bits)
    }
}

/// A wider set of framings to offer when 8N1 finds nothing. Stop bits stay at 1: a
/// receiver checks only the first stop bit, so a controller set to 2 answers 1-stop-bit
/// commands `[inferred]`; 7 data bits without parity is left out as rare `[inferred]`.
pub const MORE_FRAMINGS: [Framing; 5] = [
    Framing::EIGHT_N_ONE,
    Framing::SEVEN_E_ONE,
    Framing::EIGHT_E_ONE,
    Framing::SEVEN_O_ONE,
    Framing::EIGHT_O_ONE,
];

/// Every station, "99" first (the usual one, PROTOCOL.md 1.3), then 00 to FF.
pub fn station_sweep() -> Vec<Station> {
    std::iter::once(Station::DEFAULT)
        .chain(
            (0..=u8::MAX)
                .map(Station)
                .filter(|&s| s != Station::DEFAULT),
        )
        .collect()
}

/// One thing to try: a line setting and a station.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Candidate {
    pub line: LineSettings,
    pub station: Station,
}

impl fmt::Display for Candidate {
    /// "115200 8N1, station 99".
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}, station {}", self.line, self.station)
    }
}

/// What to try. Lists are tried in their order; duplicates are skipped.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ProbePlan {
    /// Default [`LIKELY_BAUDS`].
    pub bauds: Vec<u32>,
    /// Default 8N1 only; [`MORE_FRAMINGS`] for a wider search.
    pub framings: Vec<Framing>,
    /// Default 99 only; [`station_sweep`] for all 256 (see [`ProbePlan::estimate`]).
    pub stations: Vec<Station>,
    /// Added to the wire time of command and reply to make each probe's time-out: the
    /// controller's response delay (I/O parameter 97, PROTOCOL.md 1.5) and processing.
    /// Default 60 ms, smaller than the link's `[inferred]`.
    pub margin: Duration,
    /// Keep going after the first answer (to list every setting that answers).
    pub probe_all: bool,
}

impl Default for ProbePlan {
    fn default() -> Self {
        Self {
            bauds: LIKELY_BAUDS.to_vec(),
            framings: vec![Framing::EIGHT_N_ONE],
            stations: vec![Station::DEFAULT],
            margin: Duration::from_millis(60),
            probe_all: false,
        }
    }
}

/// Time to open and close the port once, for estimates `[inferred]`.
const OPEN_ALLOWANCE: Duration = Duration::from_millis(20);
/// Dropping stale input before each command (the transport's drain limit is 5 ms).
const DISCARD_ALLOWANCE: Duration = Duration::from_millis(5);

/// Worst-case duration of trying `candidates` in order with reply margin `margin`: each
/// silent until its time-out, plus an allowance for each (re)opening of the port and for
/// dropping stale input `[inferred allowances]`. Pure: for the panel's "about N s".
pub fn estimate_duration(candidates: &[Candidate], margin: Duration) -> Duration {
    let command_len = Command::SystemStatus
        .to_bytes(Station::DEFAULT, ScMode::Computed)
        .map_or(10, |b| b.len());
    let reply_len = Command::SystemStatus.max_reply_len();
    let mut total = Duration::ZERO;
    let mut open: Option<LineSettings> = None;
    for c in candidates {
        if open != Some(c.line) {
            total += OPEN_ALLOWANCE;
            open = Some(c.line);
        }
        let timing = Timing {
            line: c.line,
            margin,
            ..Timing::default()
        };
        total += timing.reply_timeout(command_len, reply_len) + timing.gap + DISCARD_ALLOWANCE;
    }
    total
}

fn dedup<T: PartialEq + Copy>(items: &[T]) -> Vec<T> {
    let mut out: Vec<T> = Vec::with_capacity(items.len());
    for &item in items {
        if !out.contains(&item) {
            out.push(item);
        }
    }
    out
}

impl ProbePlan {
    /// The same plan trying all 256 stations.
    pub fn with_station_sweep(mut self) -> Self {
        self.stations = station_sweep();
        self
    }

    /// The line settings in the order tried: every baud rate at the first framing, then
    /// at the next.
    pub fn settings(&self) -> Vec<LineSettings> {
        let bauds = dedup(&self.bauds);
        dedup(&self.framings)
            .into_iter()
            .flat_map(|f| bauds.iter().map(move |&b| f.at(b)))
            .collect()
    }

    /// Every candidate in the order tried: the first station at every setting, then the
    /// other stations setting by setting, so the usual station is found at any baud rate
    /// before a sweep starts (the port is opened at most twice per setting).
    pub fn candidates(&self) -> Vec<Candidate> {
        let settings = self.settings();
        let stations = dedup(&self.stations);
        let Some((&first, rest)) = stations.split_first() else {
            return Vec::new();
        };
        let firsts = settings.iter().map(|&line| Candidate {
            line,
            station: first,
        });
        let others = settings
            .iter()
            .flat_map(|&line| rest.iter().map(move |&station| Candidate { line, station }));
        firsts.chain(others).collect()
    }

    /// Worst-case duration: every candidate silent until its time-out (see
    /// [`estimate_duration`]).
    pub fn estimate(&self) -> Duration {
        estimate_duration(&self.candidates(), self.margin)
    }

    /// Refuses an empty list or a setting the line cannot take.
    pub fn validate(&self) -> Result<(), ProbeError> {
        if self.bauds.is_empty() || self.framings.is_empty() || self.stations.is_empty() {
            return Err(ProbeError::Plan(
                "give at least one baud rate, one framing and one station".into(),
            ));
        }
        for line in self.settings() {
            line.validate()
                .map_err(|e| ProbeError::Plan(format!("{line}: {e}")))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::line::STANDARD_BAUDS;

    #[test]
    fn likely_bauds_are_the_standard_ones_most_likely_first() {
        let mut sorted = LIKELY_BAUDS;
        sorted.sort_unstable();
        assert_eq!(sorted, STANDARD_BAUDS);
        assert_eq!(LIKELY_BAUDS[0], 115_200);
        assert_eq!(Framing::SEVEN_E_ONE.to_string(), "7E1");
    }

    #[test]
    fn default_plan_tries_station_99_at_each_baud_rate_in_under_a_second() {
        let plan = ProbePlan::default();
        let c = plan.candidates();
        assert_eq!(c.len(), 6);
        assert!(c.iter().all(|c| c.station == Station::DEFAULT));
        assert_eq!(c[0].to_string(), "115200 8N1, station 99");
        assert!(
            plan.estimate() < Duration::from_secs(1),
            "{:?}",
            plan.estimate()
        );
        assert!(plan.validate().is_ok());
    }

    #[test]
    fn a_sweep_tries_99_everywhere_first_then_every_station_once_per_setting() {
        let plan = ProbePlan {
            bauds: vec![9_600, 115_200, 9_600],
            framings: vec![Framing::EIGHT_N_ONE, Framing::SEVEN_E_ONE],
            ..ProbePlan::default()
        }
        .with_station_sweep();
        let c = plan.candidates();
        assert_eq!(c.len(), 4 * 256);
        let firsts: Vec<String> = c[..4].iter().map(ToString::to_string).collect();
        assert_eq!(
            firsts,
            [
                "9600 8N1, station 99",
                "115200 8N1, station 99",
                "9600 7E1, station 99",
                "115200 7E1, station 99"
            ]
        );
        assert_eq!(c[4].to_string(), "9600 8N1, station 00");
        assert_eq!(c[4 + 255].to_string(), "115200 8N1, station 00");
        let mut seen = std::collections::HashSet::new();
        assert!(c.iter().all(|c| seen.insert(c.to_string())));
        // One 9600 8N1 sweep: 256 × (35 chars ≈ 36.5 ms + 60 ms + 6 ms) ≈ 26 s.
        let one = ProbePlan {
            bauds: vec![9_600],
            ..ProbePlan::default()
        }
        .with_station_sweep();
        let t = one.estimate();
        assert!(
            t > Duration::from_secs(25) && t < Duration::from_secs(28),
            "{t:?}"
        );
    }

    #[test]
    fn empty_lists_and_bad_settings_are_refused_with_a_message() {
        let empty = ProbePlan {
            stations: Vec::new(),
            ..ProbePlan::default()
        };
        assert!(empty.candidates().is_empty());
        assert!(empty.validate().is_err());
        let bad = ProbePlan {
            bauds: vec![300],
            ..ProbePlan::default()
        };
        let msg = bad
            .validate()
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(msg.contains("300"), "{msg}");
    }
}
