//! Helpers shared by the core's integration tests: a per-thread allocation counter and the
//! continuation test problems ([`branches`]).

#![allow(dead_code)]

pub mod branches;

use std::cell::Cell;

thread_local! {
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}

/// A global allocator counting the allocations (and reallocations) of the current thread
/// (tests run on parallel threads); a test crate installs it with
/// `#[global_allocator] static ALLOCATOR: common::CountingAllocator = common::CountingAllocator;`.
pub struct CountingAllocator;

unsafe impl std::alloc::GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: std::alloc::Layout) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        unsafe { std::alloc::System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: std::alloc::Layout) {
        unsafe { std::alloc::System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: std::alloc::Layout, size: usize) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        unsafe { std::alloc::System.realloc(ptr, layout, size) }
    }
}

/// Allocations made by the current thread so far (0 unless [`CountingAllocator`] is the
/// global allocator).
pub fn allocations() -> u64 {
    ALLOCATIONS.with(Cell::get)
}
