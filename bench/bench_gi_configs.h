// The configurations `sdfstream bench gi` compares: our default, its switches and parameters
// changed one at a time, and plain DDGI built from the same code as the baseline.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "bench/bench_gi_scenes.h"
#include "gi/probe_field_frame.h"

namespace sdfstream::bench {

struct GiConfig {
  std::string name, family, change;
  probe::ProbeFieldSettings probes;
  int cascades = 1;
  bool converge = true;  // measure frames to converge after a light switch
  std::string base;      // the configuration `change` is relative to ("" = none)
  // Sampling: 1 every pixel; 2 or 4 one pixel per block of that size, the rest upsampled.
  std::uint32_t sampleBlock = 1;
};

// "chebyshev", "sdf", "chebyshev+sdf".
const char* visibilityName(probe::ProbeFieldSettings::Visibility v);

// "Plain DDGI" from the same code: a uniform grid of one probe per brick, no
// relocation, no states, no hit cache, Chebyshev visibility only.
probe::ProbeFieldSettings plainDdgi();

// The sweep: our default; the switches (hit cache, states, relocation, visibility) each changed
// alone from an ablation base; rays, spacing and cascade count changed alone from the default;
// the baseline and the baseline at other ray counts (so plain DDGI is a curve, not one point).
// Full mode: the ablation base is the default and every configuration measures convergence.
// Quick mode (lavapipe on 2 cores: a 17³ x 128-ray frame costs seconds there): the ablation base
// is spacing 2 (9³ probes per cascade, ~6x cheaper), no extra cascade counts, rays 32 only, and
// only the base measures convergence.
std::vector<GiConfig> sweepConfigs(const BenchScene& scene, bool quick);

// What --gpu-table runs: SDFDDGI's probe count, our default and plain DDGI.
std::vector<GiConfig> gpuTableConfigs(const BenchScene& scene);

}  // namespace sdfstream::bench
