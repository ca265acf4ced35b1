//! Encoding a command into a buffer that has room allocates nothing.
// A counting global allocator needs `unsafe impl GlobalAlloc`; nothing else here is unsafe.
#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicUsize, Ordering};

use xsel_pendant::protocol::*;

struct Counting;

static ALLOCS: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    /// Only the test's own thread is counted: the test harness's other threads may
    /// allocate at any moment (a busy machine makes that likely).
    static COUNT_HERE: Cell<bool> = const { Cell::new(false) };
}

fn count() {
    if COUNT_HERE.try_with(Cell::get).unwrap_or(false) {
        ALLOCS.fetch_add(1, Ordering::SeqCst);
    }
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn encoding_a_scara_move_into_a_reused_buffer_does_not_allocate() {
    let cmd = Command::ScaraMoveRelative(ScaraMove {
        motion: ScaraMotion::Cp {
            acc: CentiG(30),
            dec: CentiG(30),
            speed: MmPerSec(50),
        },
        targets: PerAxis::new()
            .with(Axis::A1, Milli(1000))
            .with(Axis::A2, Milli(-5000))
            .with(Axis::A3, Milli(0))
            .with(Axis::A4, Milli(45_000)),
    });
    let mut buf = Vec::with_capacity(128);
    let before = ALLOCS.load(Ordering::SeqCst);
    COUNT_HERE.with(|c| c.set(true));
    for _ in 0..100 {
        buf.clear();
        cmd.encode_into(Station::DEFAULT, ScMode::Computed, &mut buf)
            .unwrap();
    }
    COUNT_HERE.with(|c| c.set(false));
    let after = ALLOCS.load(Ordering::SeqCst);
    assert_eq!(after - before, 0, "allocations while encoding");
    assert_eq!(buf.len(), 58);
    assert!(buf.ends_with(b"\r\n"));
}
