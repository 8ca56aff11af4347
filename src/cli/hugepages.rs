//! A global allocator that asks Linux for transparent huge pages on large blocks.
//!
//! A 1e6-dof factorisation touches about 2.4 GB of fresh memory: with 4 KiB pages that is
//! some 780,000 page faults, a fifth of the run's CPU time on the project's machine, and
//! TLB misses in the dense kernels. The kernel there backs memory with 2 MiB pages only
//! where a program asks for it (`/sys/kernel/mm/transparent_hugepage/enabled` is
//! `madvise`, the Debian default), so blocks of at least [`HUGE_MIN_BYTES`] are marked
//! with `madvise(MADV_HUGEPAGE)` after the system allocator returns them. Measured on the
//! 1e6-dof square: page faults 778k → 40k, system time 2.9 s → 1.8 s, wall −15 %
//! (docs/performance.md). Elsewhere this is the system allocator unchanged.
//!
//! Not on a virtual machine whose balloon device reports free pages to its host
//! (virtio-balloon with `VIRTIO_BALLOON_F_REPORTING`, e.g. Firecracker): the host takes
//! back every free 2 MiB block and must back it anew at its next first touch, and a huge
//! page faulted in that way cost 3–4 s per GB there against 1–1.7 s per GB for 4 KiB
//! pages (the kernel hands small pages out of blocks it has not reported). On such a
//! machine a linear run of 5e5 dofs took 8.5–8.9 s with huge pages and 5.7–5.9 s without
//! (docs/performance.md, session 13). `SEGFEM_HUGEPAGES=on|off` overrides the choice.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicU8, Ordering};

/// Blocks from this size on are marked for huge pages [bytes] (two huge pages: smaller
/// blocks rarely contain an aligned 2 MiB range).
pub const HUGE_MIN_BYTES: usize = 4 << 20;

/// The system allocator, with large blocks marked for transparent huge pages.
pub struct HugePageAlloc;

/// Whether large blocks are marked: 0 not decided yet, 1 yes, 2 no.
static USE_HUGE: AtomicU8 = AtomicU8::new(0);

/// True if some virtio balloon device of this machine reports free pages to its host:
/// its sysfs `device` is 0x0005 (balloon) and bit 5 (`VIRTIO_BALLOON_F_REPORTING`) of its
/// negotiated `features` is set (sysfs prints one character per bit, bit 0 first).
#[cfg(target_os = "linux")]
fn free_page_reporting() -> bool {
    let Ok(dir) = std::fs::read_dir("/sys/bus/virtio/devices") else {
        return false;
    };
    dir.flatten().any(|e| {
        let read = |f: &str| std::fs::read_to_string(e.path().join(f)).unwrap_or_default();
        read("device").trim() == "0x0005" && read("features").as_bytes().get(5) == Some(&b'1')
    })
}

#[cfg(not(target_os = "linux"))]
fn free_page_reporting() -> bool {
    false
}

/// The choice for `setting` (`SEGFEM_HUGEPAGES`: `on`/`1`, `off`/`0`, else detected) and
/// whether the host takes free pages back.
fn choose(setting: Option<&str>, reporting: impl FnOnce() -> bool) -> bool {
    match setting.map(str::trim) {
        Some("on" | "1") => true,
        Some("off" | "0") => false,
        _ => !reporting(),
    }
}

/// Whether large blocks go on huge pages, decided at the first large block. (Deciding
/// allocates only small blocks, which do not come back here; two threads deciding at once
/// reach the same answer.)
fn use_huge() -> bool {
    match USE_HUGE.load(Ordering::Relaxed) {
        1 => true,
        2 => false,
        _ => {
            let setting = std::env::var("SEGFEM_HUGEPAGES").ok();
            let on = choose(setting.as_deref(), free_page_reporting);
            USE_HUGE.store(if on { 1 } else { 2 }, Ordering::Relaxed);
            on
        }
    }
}

#[cfg(target_os = "linux")]
fn advise(ptr: *mut u8, size: usize) {
    const MADV_HUGEPAGE: i32 = 14;
    const PAGE: usize = 4096;
    extern "C" {
        fn madvise(addr: *mut u8, len: usize, advice: i32) -> i32;
    }
    if !use_huge() {
        return;
    }
    // madvise wants a page-aligned start; the kernel applies it to the whole 2 MiB ranges
    // inside. The result is ignored: the advice is an optimisation only.
    let start = (ptr as usize).next_multiple_of(PAGE);
    let end = (ptr as usize + size) & !(PAGE - 1);
    if end > start {
        // SAFETY: the range lies inside a block just returned by the system allocator;
        // MADV_HUGEPAGE changes no contents and no permissions.
        unsafe {
            madvise(start as *mut u8, end - start, MADV_HUGEPAGE);
        }
    }
}

#[cfg(not(target_os = "linux"))]
fn advise(_ptr: *mut u8, _size: usize) {}

// SAFETY: every call is forwarded to `System` with the same arguments; `advise` only adds
// a hint on memory the caller now owns.
unsafe impl GlobalAlloc for HugePageAlloc {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = System.alloc(layout);
        if !p.is_null() && layout.size() >= HUGE_MIN_BYTES {
            advise(p, layout.size());
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let p = System.alloc_zeroed(layout);
        if !p.is_null() && layout.size() >= HUGE_MIN_BYTES {
            advise(p, layout.size());
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = System.realloc(ptr, layout, new_size);
        if !p.is_null() && new_size >= HUGE_MIN_BYTES {
            advise(p, new_size);
        }
        p
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Large and small blocks allocate, hold data and free through the wrapper.
    #[test]
    fn allocates_large_and_small_blocks() {
        let a = HugePageAlloc;
        for size in [64, HUGE_MIN_BYTES, 3 * HUGE_MIN_BYTES + 5] {
            let layout = Layout::from_size_align(size, 8).unwrap();
            unsafe {
                let p = a.alloc_zeroed(layout);
                assert!(!p.is_null());
                assert_eq!(*p.add(size - 1), 0);
                *p.add(size - 1) = 7;
                let q = a.realloc(p, layout, 2 * size);
                assert_eq!(*q.add(size - 1), 7);
                a.dealloc(q, Layout::from_size_align(2 * size, 8).unwrap());
            }
        }
    }

    /// The setting wins over the detection; without one, huge pages unless the host takes
    /// free pages back.
    #[test]
    fn setting_and_detection() {
        let never = || -> bool { panic!("detection not wanted with a setting") };
        assert!(choose(Some("on"), never));
        assert!(choose(Some(" 1"), never));
        assert!(!choose(Some("off"), never));
        assert!(!choose(Some("0\n"), never));
        assert!(choose(None, || false));
        assert!(!choose(None, || true));
        assert!(choose(Some("auto"), || false));
        assert!(!choose(Some(""), || true));
    }
}
