//! Seeded fault injection on the simulator's replies: drop, corrupt SC, garbage, delay
//! past a timeout, truncate, stall the line; with a count of each fault injected.

use std::fmt;
use std::str::FromStr;
use std::time::Duration;

/// One kind of fault.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Fault {
    /// The reply is not sent.
    Drop,
    /// The reply's SC is replaced by a wrong one.
    Corrupt,
    /// Noise bytes (no `#`, `&`, `!`, CR or LF) are sent before the reply.
    Garbage,
    /// The reply is sent only after `delay` (longer than a client's timeout).
    Delay,
    /// Only the first part of the reply is sent (never its LF).
    Truncate,
    /// The reply is sent in two parts with the line silent for `stall` between them.
    Stall,
}

impl Fault {
    pub const ALL: [Fault; 6] = [
        Fault::Drop,
        Fault::Corrupt,
        Fault::Garbage,
        Fault::Delay,
        Fault::Truncate,
        Fault::Stall,
    ];

    /// The key used in a fault spec.
    pub fn key(self) -> &'static str {
        match self {
            Fault::Drop => "drop",
            Fault::Corrupt => "corrupt",
            Fault::Garbage => "garbage",
            Fault::Delay => "delay",
            Fault::Truncate => "truncate",
            Fault::Stall => "stall",
        }
    }

    fn index(self) -> usize {
        self as usize
    }
}

/// Probabilities per reply and the seed: `drop=0.05,corrupt=0.02,seed=7`.
///
/// Keys: `drop`, `corrupt`, `garbage`, `delay`, `truncate`, `stall` (probability 0..1 per
/// reply; at most one fault per reply, so they must sum to at most 1), `seed` (u64),
/// `delay-ms` (how late a delayed reply comes, default 1500), `stall-ms` (how long a
/// stalled line stays silent mid-reply, default 300).
#[derive(Debug, Clone, PartialEq)]
pub struct FaultSpec {
    pub probability: [f64; 6],
    pub seed: u64,
    pub delay: Duration,
    pub stall: Duration,
}

impl Default for FaultSpec {
    fn default() -> Self {
        Self {
            probability: [0.0; 6],
            seed: 1,
            delay: Duration::from_millis(1500),
            stall: Duration::from_millis(300),
        }
    }
}

impl FaultSpec {
    /// No faults at all.
    pub fn none() -> Self {
        Self::default()
    }

    /// True when some fault has a non-zero probability.
    pub fn is_active(&self) -> bool {
        self.probability.iter().any(|&p| p > 0.0)
    }

    /// Sets one probability (builder style).
    pub fn with(mut self, fault: Fault, probability: f64) -> Self {
        self.probability[fault.index()] = probability;
        self
    }

    /// Sets the seed (builder style).
    pub fn seeded(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }
}

/// Why a fault spec could not be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FaultSpecError {
    #[error(
        "`{0}` is not key=value (keys: drop, corrupt, garbage, delay, truncate, stall, seed, delay-ms, stall-ms)"
    )]
    Syntax(String),
    #[error(
        "unknown fault key `{0}` (keys: drop, corrupt, garbage, delay, truncate, stall, seed, delay-ms, stall-ms)"
    )]
    Key(String),
    #[error("`{0}`: a probability between 0 and 1 was expected")]
    Probability(String),
    #[error("`{0}`: a whole number was expected")]
    Number(String),
    #[error("the fault probabilities add up to {0:.3}, more than 1")]
    Sum(f64),
}

impl FromStr for FaultSpec {
    type Err = FaultSpecError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let mut spec = FaultSpec::default();
        for item in s.split(',').map(str::trim).filter(|i| !i.is_empty()) {
            let (key, value) = item
                .split_once('=')
                .ok_or_else(|| FaultSpecError::Syntax(item.to_owned()))?;
            let (key, value) = (key.trim(), value.trim());
            let number = || {
                value
                    .parse::<u64>()
                    .map_err(|_| FaultSpecError::Number(item.to_owned()))
            };
            match key {
                "seed" => spec.seed = number()?,
                "delay-ms" => spec.delay = Duration::from_millis(number()?),
                "stall-ms" => spec.stall = Duration::from_millis(number()?),
                _ => {
                    let fault = Fault::ALL
                        .into_iter()
                        .find(|f| f.key() == key)
                        .ok_or_else(|| FaultSpecError::Key(key.to_owned()))?;
                    let p: f64 = value
                        .parse()
                        .ok()
                        .filter(|p: &f64| (0.0..=1.0).contains(p))
                        .ok_or_else(|| FaultSpecError::Probability(item.to_owned()))?;
                    spec.probability[fault.index()] = p;
                }
            }
        }
        let sum: f64 = spec.probability.iter().sum();
        if sum > 1.0 + 1e-9 {
            return Err(FaultSpecError::Sum(sum));
        }
        Ok(spec)
    }
}

impl fmt::Display for FaultSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for fault in Fault::ALL {
            let p = self.probability[fault.index()];
            if p > 0.0 {
                write!(f, "{}={},", fault.key(), p)?;
            }
        }
        write!(
            f,
            "seed={},delay-ms={},stall-ms={}",
            self.seed,
            self.delay.as_millis(),
            self.stall.as_millis()
        )
    }
}

/// How many faults of each kind were injected, and how many replies passed clean.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FaultCounts {
    pub drop: u64,
    pub corrupt: u64,
    pub garbage: u64,
    pub delay: u64,
    pub truncate: u64,
    pub stall: u64,
    /// Replies sent without a fault.
    pub clean: u64,
}

impl FaultCounts {
    /// Count of one kind.
    pub fn get(&self, fault: Fault) -> u64 {
        match fault {
            Fault::Drop => self.drop,
            Fault::Corrupt => self.corrupt,
            Fault::Garbage => self.garbage,
            Fault::Delay => self.delay,
            Fault::Truncate => self.truncate,
            Fault::Stall => self.stall,
        }
    }

    /// All faults injected.
    pub fn total(&self) -> u64 {
        Fault::ALL.iter().map(|&f| self.get(f)).sum()
    }

    fn bump(&mut self, fault: Fault) {
        match fault {
            Fault::Drop => self.drop += 1,
            Fault::Corrupt => self.corrupt += 1,
            Fault::Garbage => self.garbage += 1,
            Fault::Delay => self.delay += 1,
            Fault::Truncate => self.truncate += 1,
            Fault::Stall => self.stall += 1,
        }
    }
}

/// A piece of a reply's delivery: wait `pause` (after the previous piece), then send.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Piece {
    pub pause: Duration,
    pub bytes: Vec<u8>,
}

/// What goes on the line for one reply; empty when the reply is dropped.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Delivery {
    pub fault: Option<Fault>,
    pub pieces: Vec<Piece>,
}

/// A small, fast, seedable generator (SplitMix64); no external crate needed.
#[derive(Debug, Clone)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `lo..hi` (`lo` when the range is empty).
    pub fn range(&mut self, lo: usize, hi: usize) -> usize {
        if hi <= lo {
            return lo;
        }
        lo + (self.next_u64() % (hi - lo) as u64) as usize
    }
}

/// Decides, reply by reply, which fault (if any) to inject.
#[derive(Debug, Clone)]
pub struct FaultInjector {
    spec: FaultSpec,
    rng: SplitMix64,
    counts: FaultCounts,
}

impl FaultInjector {
    pub fn new(spec: FaultSpec) -> Self {
        let rng = SplitMix64::new(spec.seed);
        Self {
            spec,
            rng,
            counts: FaultCounts::default(),
        }
    }

    pub fn spec(&self) -> &FaultSpec {
        &self.spec
    }

    /// Replaces the spec and restarts the generator from its seed (counts are kept).
    pub fn set_spec(&mut self, spec: FaultSpec) {
        self.rng = SplitMix64::new(spec.seed);
        self.spec = spec;
    }

    pub fn counts(&self) -> FaultCounts {
        self.counts
    }

    /// Plans the delivery of one complete reply (ending in CR LF).
    pub fn plan(&mut self, reply: &[u8]) -> Delivery {
        let fault = self.pick();
        let piece = |pause, bytes: &[u8]| Piece {
            pause,
            bytes: bytes.to_vec(),
        };
        let mut pieces = Vec::with_capacity(2);
        match fault {
            None => {
                self.counts.clean += 1;
                pieces.push(piece(Duration::ZERO, reply));
            }
            Some(f) => {
                self.counts.bump(f);
                match f {
                    Fault::Drop => {}
                    Fault::Corrupt => {
                        let mut bytes = reply.to_vec();
                        corrupt_sc(&mut bytes, &mut self.rng);
                        pieces.push(Piece {
                            pause: Duration::ZERO,
                            bytes,
                        });
                    }
                    Fault::Garbage => {
                        let n = self.rng.range(1, 9);
                        let mut bytes: Vec<u8> =
                            (0..n).map(|_| noise_byte(&mut self.rng)).collect();
                        bytes.extend_from_slice(reply);
                        pieces.push(Piece {
                            pause: Duration::ZERO,
                            bytes,
                        });
                    }
                    Fault::Delay => pieces.push(piece(self.spec.delay, reply)),
                    Fault::Truncate => {
                        // Keep at least one byte, never the LF.
                        let keep = self.rng.range(1, reply.len().saturating_sub(1).max(2));
                        pieces.push(piece(Duration::ZERO, &reply[..keep.min(reply.len())]));
                    }
                    Fault::Stall => {
                        let cut = self.rng.range(1, reply.len().max(2));
                        let cut = cut.min(reply.len());
                        pieces.push(piece(Duration::ZERO, &reply[..cut]));
                        pieces.push(piece(self.spec.stall, &reply[cut..]));
                    }
                }
            }
        }
        Delivery { fault, pieces }
    }

    fn pick(&mut self) -> Option<Fault> {
        if !self.spec.is_active() {
            return None;
        }
        let r = self.rng.next_f64();
        let mut acc = 0.0;
        for fault in Fault::ALL {
            acc += self.spec.probability[fault.index()];
            if r < acc {
                return Some(fault);
            }
        }
        None
    }
}

/// Replaces the two SC digits before CR LF by a different, still well-formed value.
fn corrupt_sc(bytes: &mut [u8], rng: &mut SplitMix64) {
    let n = bytes.len();
    if n < 4 {
        return;
    }
    let sc = &mut bytes[n - 4..n - 2];
    let old = std::str::from_utf8(sc)
        .ok()
        .and_then(crate::protocol::peek::hex_digits)
        .unwrap_or(0) as u8;
    let new = old.wrapping_add(1 + (rng.next_u64() % 255) as u8);
    let hex = format!("{new:02X}");
    sc.copy_from_slice(hex.as_bytes());
}

fn noise_byte(rng: &mut SplitMix64) -> u8 {
    loop {
        let b = (rng.next_u64() & 0xFF) as u8;
        if !matches!(b, b'#' | b'&' | b'!' | b'\r' | b'\n') {
            return b;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const REPLY: &[u8] = b"#992322C\r\n";

    #[test]
    fn spec_parses_and_rejects() {
        let s: FaultSpec = "drop=0.05, corrupt=0.02,seed=7,delay-ms=900"
            .parse()
            .unwrap();
        assert_eq!(s.probability[0], 0.05);
        assert_eq!(s.probability[1], 0.02);
        assert_eq!(s.seed, 7);
        assert_eq!(s.delay, Duration::from_millis(900));
        assert!("drop=2".parse::<FaultSpec>().is_err());
        assert!("flip=0.1".parse::<FaultSpec>().is_err());
        assert!("drop".parse::<FaultSpec>().is_err());
        assert!("drop=0.6,stall=0.6".parse::<FaultSpec>().is_err());
        assert!(!"".parse::<FaultSpec>().unwrap().is_active());
    }

    #[test]
    fn no_spec_no_fault() {
        let mut inj = FaultInjector::new(FaultSpec::none());
        for _ in 0..100 {
            let d = inj.plan(REPLY);
            assert_eq!(d.pieces.len(), 1);
            assert_eq!(d.pieces[0].bytes, REPLY);
        }
        assert_eq!(inj.counts().clean, 100);
        assert_eq!(inj.counts().total(), 0);
    }

    #[test]
    fn every_fault_shapes_the_reply_and_is_counted() {
        for fault in Fault::ALL {
            let mut inj = FaultInjector::new(FaultSpec::none().with(fault, 1.0).seeded(3));
            for _ in 0..50 {
                let d = inj.plan(REPLY);
                assert_eq!(d.fault, Some(fault));
                let sent: Vec<u8> = d.pieces.iter().flat_map(|p| p.bytes.clone()).collect();
                match fault {
                    Fault::Drop => assert!(sent.is_empty()),
                    Fault::Corrupt => {
                        assert_eq!(sent.len(), REPLY.len());
                        assert_ne!(sent, REPLY);
                        assert_eq!(&sent[..6], &REPLY[..6]);
                    }
                    Fault::Garbage => {
                        assert!(sent.ends_with(REPLY) && sent.len() > REPLY.len());
                        let noise = &sent[..sent.len() - REPLY.len()];
                        assert!(!noise.iter().any(|b| b"#&!\r\n".contains(b)));
                    }
                    Fault::Delay => assert_eq!(d.pieces[0].pause, Duration::from_millis(1500)),
                    Fault::Truncate => {
                        assert!(!sent.is_empty() && sent.len() < REPLY.len());
                        assert!(!sent.contains(&b'\n'));
                    }
                    Fault::Stall => {
                        assert_eq!(sent, REPLY);
                        assert_eq!(d.pieces.len(), 2);
                    }
                }
            }
            assert_eq!(inj.counts().get(fault), 50);
            assert_eq!(inj.counts().total(), 50);
        }
    }

    #[test]
    fn same_seed_same_faults() {
        let spec: FaultSpec = "drop=0.2,corrupt=0.2,seed=42".parse().unwrap();
        let run = |spec: &FaultSpec| {
            let mut inj = FaultInjector::new(spec.clone());
            (0..200).map(|_| inj.plan(REPLY).fault).collect::<Vec<_>>()
        };
        assert_eq!(run(&spec), run(&spec));
        let mut inj = FaultInjector::new(spec);
        for _ in 0..2000 {
            inj.plan(REPLY);
        }
        let c = inj.counts();
        assert!((300..500).contains(&c.drop), "{c:?}");
        assert!((300..500).contains(&c.corrupt), "{c:?}");
    }
}
