//! The sample store: exact read-back, the ring bound, min/max decimation.

use std::time::{Duration, Instant};

use proptest::prelude::*;

use super::*;

fn store(cap: usize) -> (SampleStore, SeriesId, Instant) {
    let mut s = SampleStore::default();
    let id = s.add(
        "Axis 1",
        vec![
            Channel::new("Actual Position", "pu"),
            Channel::new("Target Velocity", "pu/s"),
            Channel::level("In Position"),
        ],
        Encoding::Real,
        cap,
    );
    (s, id, Instant::now())
}

#[test]
fn a_million_samples_read_back_exactly() {
    let (mut s, id, t0) = store(1_000_000);
    let value =
        |i: u32| f32::from_bits(0x3F80_0000 ^ (i.wrapping_mul(2_654_435_761) & 0x007F_FFFF));
    for i in 0..1_000_000u32 {
        let at = t0 + Duration::from_micros(u64::from(i) * 20_000);
        s.push(
            id,
            at,
            &[
                Sample::Real(value(i)),
                Sample::Real(-value(i)),
                Sample::Level((i % 2) as u8),
            ],
        );
    }
    let series = s.series(id).unwrap();
    assert_eq!(series.len(), 1_000_000);
    for i in (0..1_000_000u32).step_by(997).chain([999_999]) {
        let row = i as usize;
        assert_eq!(
            series.time(row),
            Some(Duration::from_micros(u64::from(i) * 20_000))
        );
        assert_eq!(series.raw(row, 0), Some(value(i).to_bits()));
        assert_eq!(series.value(row, 1), Some(f64::from(-value(i))));
        assert_eq!(series.value(row, 2), Some(f64::from(i % 2)));
    }
    // 20 bytes a row (time and three values) and, per 16 rows, each channel's min and
    // max (8 bytes).
    assert_eq!(series.bytes(), 1_000_000 * 20 + 1_000_000 / 16 * 3 * 8);
}

#[test]
fn the_ring_keeps_the_newest_rows_up_to_its_bound() {
    let (mut s, id, t0) = store(1000);
    for i in 0..2500u32 {
        s.push(
            id,
            t0 + Duration::from_millis(u64::from(i)),
            &[Sample::Real(i as f32)],
        );
    }
    let series = s.series(id).unwrap();
    assert_eq!(series.len(), 1000);
    assert_eq!(series.dropped, 1500);
    assert_eq!(series.value(0, 0), Some(1500.0));
    assert_eq!(series.value(999, 0), Some(2499.0));
    assert_eq!(series.value(0, 1), Some(0.0), "a value not given is 0");
}

#[test]
fn thousandths_read_back_as_polled() {
    let mut s = SampleStore::default();
    let id = s.add("X-SEL", vec![Channel::new("X", "mm")], Encoding::Milli, 10);
    let t0 = Instant::now();
    s.push(id, t0, &[Sample::Milli(250_123)]);
    s.push(id, t0 - Duration::from_millis(5), &[Sample::Milli(-1)]);
    let series = s.series(id).unwrap();
    assert_eq!(series.value(0, 0), Some(250.123));
    assert_eq!(series.value(1, 0), Some(-0.001));
    assert_eq!(series.time(1), Some(Duration::ZERO), "time never goes back");
}

proptest! {
    #[test]
    fn decimation_keeps_each_columns_min_and_max(
        values in prop::collection::vec(-1e6f32..1e6, 1..400),
        columns in 1usize..64,
    ) {
        let (mut s, id, t0) = store(10_000);
        for (i, v) in values.iter().enumerate() {
            s.push(id, t0 + Duration::from_millis(i as u64 * 7), &[Sample::Real(*v)]);
        }
        let series = s.series(id).unwrap();
        let to = Duration::from_millis(values.len() as u64 * 7);
        let got = series.min_max(0, Duration::ZERO, to, columns);
        let span = to.as_nanos();
        let mut want = vec![None::<(f64, f64)>; columns];
        for (i, v) in values.iter().enumerate() {
            let t = Duration::from_millis(i as u64 * 7).as_nanos();
            let c = ((t * columns as u128) / span) as usize;
            let v = f64::from(*v);
            let slot = &mut want[c.min(columns - 1)];
            *slot = Some(slot.map_or((v, v), |(lo, hi)| (lo.min(v), hi.max(v))));
        }
        prop_assert_eq!(got, want);
    }
}

proptest! {
    #[test]
    fn decimation_by_blocks_equals_every_sample_read_one_by_one(
        values in prop::collection::vec(-1e6f32..1e6, 1..3000),
        cap in 20usize..1500,
        columns in 1usize..40,
        from_ms in 0u64..10_000,
        len_ms in 1u64..25_000,
    ) {
        let (mut s, id, t0) = store(cap);
        for (i, v) in values.iter().enumerate() {
            s.push(id, t0 + Duration::from_millis(i as u64 * 7), &[Sample::Real(*v)]);
        }
        let series = s.series(id).unwrap();
        let (from, to) = (Duration::from_millis(from_ms), Duration::from_millis(from_ms + len_ms));
        let got = series.min_max(0, from, to, columns);
        let (start, span) = (from.as_nanos(), (to - from).as_nanos());
        let mut want = vec![None::<(f64, f64)>; columns];
        for row in 0..series.len() {
            let t = series.time(row).unwrap();
            if t < from || t > to {
                continue;
            }
            let c = (((t.as_nanos() - start) * columns as u128) / span) as usize;
            let v = series.value(row, 0).unwrap();
            let slot = &mut want[c.min(columns - 1)];
            *slot = Some(slot.map_or((v, v), |(lo, hi)| (lo.min(v), hi.max(v))));
        }
        prop_assert_eq!(got, want);
    }
}

#[test]
fn an_hour_of_the_pendants_polls_is_bounded_and_under_30_mb() {
    use super::polled::{HOUR_ROWS, Polled};
    use crate::rmc::{AxisId, AxisStatus};
    let mut p = Polled::new(2);
    let t0 = Instant::now();
    let status = AxisStatus {
        command_position: 10.0,
        target_position: 10.0,
        actual_position: 9.5,
        ..Default::default()
    };
    for i in 0..(HOUR_ROWS + 10) as u64 {
        let at = t0 + Duration::from_millis(i * 20);
        p.xsel_work(at, [250_000, 250_000, 0, 90_000], true, 0);
        p.xsel_joints(at, [0, 90_000, 0, 0]);
        for axis in AxisId::first(2) {
            p.rmc_status(at, axis, &status);
        }
    }
    let axis0 = p
        .store
        .series(p.rmc_series(AxisId::new(0).unwrap()).unwrap())
        .unwrap();
    assert_eq!(axis0.len(), HOUR_ROWS, "the ring's bound");
    assert_eq!(
        axis0.value(0, 5),
        Some(0.5),
        "following error: Target - Actual"
    );
    let bytes = p.store.bytes();
    assert!(bytes <= 30_000_000, "an hour takes {bytes} bytes");
}

proptest! {
    #[test]
    fn a_kept_trace_grown_row_by_row_equals_one_worked_out_afresh(
        values in prop::collection::vec(-1e3f32..1e3, 2..600),
        columns in 1usize..50,
        cut in 1usize..600,
    ) {
        use super::view::{TraceCache, TraceChoice, live_trace};
        let (mut s, id, t0) = store(10_000);
        let choice = TraceChoice::new("Axis 1", "Actual Position");
        let mut cache = TraceCache::default();
        let to = values.len() as f64 * 0.007 + 0.5;
        let cut = cut.min(values.len());
        for (k, part) in [&values[..cut], &values[cut..]].iter().enumerate() {
            for (i, v) in part.iter().enumerate() {
                let n = if k == 0 { i } else { cut + i };
                s.push(id, t0 + Duration::from_millis(n as u64 * 7), &[Sample::Real(*v)]);
            }
            let kept = cache.trace(&s, &choice, 0.0, to, columns).unwrap();
            let fresh = live_trace(&s, &choice, 0.0, to, columns).unwrap();
            prop_assert_eq!(kept.points, fresh.points);
        }
    }
}
