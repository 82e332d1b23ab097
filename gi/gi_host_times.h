// CPU time of a GI frame's host work, by part (GiFrameStats::host); its own header so harnesses
// that report it need not include the GPU system.
#pragma once

namespace sdfstream {

// Milliseconds inside GiSystem::record()/update(): building and writing into the staging ring
// what the GPU reads, and recording the passes. Waits for the GPU are not included (update's
// submit and wait come after).
struct GiHostTimes {
  double sceneMs = 0.0;             // page tables and streamed bricks
  double objectsMs = 0.0;           // instances into stack space, region state, their uploads
  double objectsBuildMs = 0.0;      // ... of which building them (buildObjectFrame, card slots)
  double objectsInstancesMs = 0.0;  // ... ... the instances into stack space
  double objectsWakeMs = 0.0;       // ... ... the changed boxes and the probes' wake bits
  double objectsCardsMs = 0.0;      // ... ... the card light blocks and the relight list
  // The light-cache pages the objects' moves shadow: found on another thread during objectsMs
  // (its own time, overlapping that one; not to be added to it).
  double shadowPagesMs = 0.0;
  double lightMs = 0.0;             // dirty pages, lights, the light cache pass
  double probesMs = 0.0;            // the probe passes
  double totalMs = 0.0;             // all of the frame's recording
};

}  // namespace sdfstream
