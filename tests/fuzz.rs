//! Fixed-seed fuzz batch of every reader (src/fuzz.rs): no input may panic, and no input may
//! make the process allocate more than a stated bound. A counting allocator measures the peak.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use hairmesh::fuzz::{Reader, campaign};

struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);
/// The readers run one at a time so the peak belongs to one of them.
static SERIAL: Mutex<()> = Mutex::new(());

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let live = LIVE.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
        PEAK.fetch_max(live, Ordering::Relaxed);
        // SAFETY: forwarded to the system allocator with the caller's layout.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
        // SAFETY: `ptr` came from `alloc` with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Inputs per reader in CI (a few seconds in total on the 2-core CI machine).
const BATCH: u64 = 3000;
/// Most memory any single reader may have live at once while fuzzing.
const MAX_LIVE_BYTES: usize = 256 << 20;

fn check(reader: Reader) {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let base = LIVE.load(Ordering::Relaxed);
    PEAK.store(base, Ordering::Relaxed);
    // The glTF seed is a whole character (470 KB, 14,000 vertices): fewer, slower inputs.
    let batch = if matches!(reader, Reader::Gltf | Reader::GltfExternal) {
        BATCH / 10
    } else {
        BATCH
    };
    let report = campaign(reader, batch, 20261125);
    let peak = PEAK.load(Ordering::Relaxed) - base;
    println!(
        "{reader:?}: {} inputs, {} accepted, {} rejected, {} panics, slowest {:.1} ms, peak {:.1} MiB",
        report.inputs,
        report.accepted,
        report.rejected,
        report.panics.len(),
        report.slowest_ms,
        peak as f64 / (1 << 20) as f64
    );
    assert!(
        report.panics.is_empty(),
        "{reader:?} panics: {:?}",
        report.panics
    );
    assert!(
        report.rejected > report.inputs / 10,
        "mutations must reach the checks"
    );
    assert!(report.accepted > 0, "some mutations stay valid");
    assert!(
        peak < MAX_LIVE_BYTES,
        "{reader:?} allocated {peak} bytes at once"
    );
}

#[test]
fn fuzz_obj_reader() {
    check(Reader::Obj);
}

#[test]
fn fuzz_style_reader() {
    check(Reader::Style);
}

#[test]
fn fuzz_scene_reader() {
    check(Reader::Scene);
}

#[test]
fn fuzz_hmb_reader() {
    check(Reader::Hmb);
}

#[test]
fn fuzz_hair_reader() {
    check(Reader::Hair);
}

#[test]
fn fuzz_tfx_reader() {
    check(Reader::Tfx);
}

#[test]
fn fuzz_fit_head_reader() {
    check(Reader::Head);
}

#[test]
fn fuzz_scene_files_reader() {
    check(Reader::SceneFiles);
}

#[test]
fn fuzz_gltf_reader() {
    check(Reader::Gltf);
}

#[test]
fn fuzz_gltf_external_buffer_reader() {
    check(Reader::GltfExternal);
}
