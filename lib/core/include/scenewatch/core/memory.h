#pragma once
/// Process-wide allocator settings for long-running frame processing.

namespace scenewatch {

/// Keeps freed frame-sized buffers (images, maps: megabytes each) in the heap for reuse instead of
/// returning them to the kernel (glibc's mmap threshold and trim threshold raised). Every frame
/// allocates such buffers anew; unmapped, each of their pages faults again on first touch, which
/// costs more than the per-pixel arithmetic (about 5 ms per VGA surprise map measured in a VM).
/// The price: the process keeps its peak heap. Call once at start-up; no-op outside glibc.
void keep_frame_buffers_in_heap();

/// Hands the heap's free pages back to the kernel (glibc's malloc_trim) that
/// keep_frame_buffers_in_heap() would keep: call where frame-sized buffers were freed and will
/// not be needed again soon (a client that held them went away), not per frame. Calls that
/// arrive while one runs are folded into it. Thread safe; no-op outside glibc.
void give_back_free_memory();

/// Resident size (VmRSS) of process `pid` in MiB, read from /proc; 0 when it cannot be read.
/// `pid` 0: this process.
double resident_mib(int pid = 0);

}  // namespace scenewatch
