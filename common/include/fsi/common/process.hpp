#pragma once
// Process-wide settings every executable applies first thing in main().
namespace fsi {
// Keeps large interface buffers (hundreds of KB per message) in the heap instead of fresh
// mmap'ed pages per call: measured 4.6 ms -> 0.5 ms per coupling iteration at 10,000
// interface nodes (bench/messaging/README.md).
void init_process();
}  // namespace fsi
