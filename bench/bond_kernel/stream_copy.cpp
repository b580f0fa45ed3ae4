// A stream-like copy (a[i] = b[i]) and triad (a[i] = b[i] + s c[i]) over
// arrays of a given size, for a roofline-style figure of the machine: bytes
// moved per second counting each array read or written once (no
// write-allocate). Build and run:
//   g++ -O2 -march=native -o /tmp/stream_copy bench/bond_kernel/stream_copy.cpp
//   /tmp/stream_copy 268435456   # 256 MB per array: main memory
//   /tmp/stream_copy 1048576     # 1 MB per array: the caches (3 arrays ~ L2/L3)
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

int main(int argc, char **argv) {
  const size_t bytes = argc > 1 ? std::strtoull(argv[1], nullptr, 10) : (256u << 20);
  const size_t n = bytes / sizeof(double);
  std::vector<double> a(n, 0.0), b(n, 1.0), c(n, 2.0);
  // Enough repeats for about 2 GB of traffic per kernel, best of them.
  const int reps = static_cast<int>(std::max<size_t>(5, (size_t(2) << 30) / bytes));
  double best_copy = 1e30, best_triad = 1e30;
  for (int r = 0; r < reps; ++r) {
    auto t0 = std::chrono::steady_clock::now();
    for (size_t i = 0; i < n; ++i) a[i] = b[i];
    auto t1 = std::chrono::steady_clock::now();
    for (size_t i = 0; i < n; ++i) a[i] = b[i] + 3.0 * c[i];
    auto t2 = std::chrono::steady_clock::now();
    best_copy = std::min(best_copy, std::chrono::duration<double>(t1 - t0).count());
    best_triad = std::min(best_triad, std::chrono::duration<double>(t2 - t1).count());
    b[r % n] += a[(r * 7) % n];  // keep the loops from being folded away
  }
  std::printf("array %.3g MB, %d repeats: copy %.2f GB/s (2 arrays), triad %.2f GB/s (3 arrays)\n",
              bytes / 1e6, reps, 2.0 * bytes / best_copy / 1e9, 3.0 * bytes / best_triad / 1e9);
  return a[n / 2] > 1e300 ? 1 : 0;
}
