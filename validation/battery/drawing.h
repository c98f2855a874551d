// The battery's random streams, threads and draws (internal to the battery).
#pragma once

#include <atomic>
#include <cstdint>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "warpcheck/validation/battery.h"

namespace warpcheck::validation::battery {

// Independent, reproducible stream per (seed, sampler, purpose, chunk): the battery is deterministic whatever
// the thread count. Purposes: 1 the draws, 2 pdf-consistency, 3 no-sample.
std::mt19937_64 stream(std::uint64_t seed, const SamplerUnderTest& s, std::uint64_t purpose, std::uint64_t chunk);

inline double uniform01(std::mt19937_64& g) { return double(g() >> 11) * 0x1.0p-53; }  // in [0, 1)

// The machine epsilon of a sampler's scalar type ("float", "double", "long double"; others as double).
Real scalar_epsilon(const std::string& scalar);

int thread_count(const BatteryOptions& o);  // options.threads, or the hardware's when 0

// Runs body(i) for i in [0, n) on `threads` threads.
template <class F> void parallel_for(std::size_t n, int threads, F&& body) {
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t i; (i = next.fetch_add(1)) < n;) body(i);
  };
  std::vector<std::thread> pool;
  for (int k = 1; k < threads; ++k) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
}

// Throws std::invalid_argument when a block form of the sampler (sample_block, pdf_block) disagrees with its
// single form (sample, pdf) at a few fixed primary samples and directions, bit for bit: a block form that
// bind_kernel filled and that was left behind when sample or pdf was replaced would otherwise be tested instead.
void check_block_forms(const SamplerUnderTest& s);

struct Draws {
  std::vector<double> t, phi;         // cap coordinates; +inf for samples outside the cap or declined
  std::vector<std::uint64_t> counts;  // chi-square grid counts
  std::uint64_t outside = 0, declined = 0, non_finite = 0;
};

// options.samples draws of the sampler from options.seed, in cap coordinates and counted on the chi-square grid.
Draws draw(const SamplerUnderTest& s, const BatteryOptions& o);

}  // namespace warpcheck::validation::battery
