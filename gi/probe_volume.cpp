#include "gi/probe_volume.h"

#include <cassert>
#include <cstring>

namespace sdfstream::probe {
namespace {
using gpu_shared::ProbeUpdatePushConstants;
constexpr glm::uvec3 kGroup(64, 1, 1);

template <typename T>
void uploadVector(gpu::Context& ctx, gpu::Buffer& buffer, const std::vector<T>& data) {
  const std::size_t bytes = data.size() * sizeof(T);
  if (buffer.size() < bytes) buffer = gpu::Buffer(ctx, bytes, gpu::BufferKind::DeviceLocal);
  if (bytes) buffer.upload(data.data(), bytes);
}
}  // namespace

ProbeVolume::ProbeVolume(gpu::Context& context, const ProbeVolumeSettings& settings)
    : context_(context),
      settings_(settings),
      trace_(context, gpu::ShaderId::probe_trace,
             gpu::PipelineDesc{8, sizeof(ProbeUpdatePushConstants), kGroup}),
      blend_(context, gpu::ShaderId::probe_blend,
             gpu::PipelineDesc{4, sizeof(ProbeUpdatePushConstants), kGroup}),
      sample_(context, gpu::ShaderId::probe_sample,
              gpu::PipelineDesc{5, sizeof(ProbeUpdatePushConstants), kGroup}),
      volume_(context, sizeof(gpu_shared::ProbeVolume), gpu::BufferKind::Upload),
      irradiance_(context, irradianceTexelCount(settings) * sizeof(glm::vec4),
                  gpu::BufferKind::DeviceLocal),
      depth_(context, depthTexelCount(settings) * sizeof(glm::vec2), gpu::BufferKind::DeviceLocal),
      rays_(context, rayCount(settings) * sizeof(glm::vec4), gpu::BufferKind::DeviceLocal) {
  reset();
}

void ProbeVolume::reset() {
  const std::vector<glm::vec4> irr(irradianceTexelCount(settings_), glm::vec4(0.0f));
  const std::vector<glm::vec2> dep(depthTexelCount(settings_), glm::vec2(0.0f));
  irradiance_.upload(irr.data(), irr.size() * sizeof(glm::vec4));
  depth_.upload(dep.data(), dep.size() * sizeof(glm::vec2));
  firstUpdate_ = true;
  const gpu_shared::ProbeVolume v = volumeParams(settings_, 0);  // sample() before any update
  std::memcpy(volume_.mapped(), &v, sizeof v);
}

void ProbeVolume::uploadScene(const CascadeStackImage& stack) {
  cascadeCount_ = std::uint32_t(stack.params.size());
  uploadVector(context_, pageTables_, stack.pageTables);
  uploadVector(context_, params_, stack.params);
  uploadVector(context_, distance_, *stack.distanceAtlas);
  uploadVector(context_, albedo_, *stack.albedoAtlas);
  uploadVector(context_, emission_, *stack.emissionAtlas);
}

void ProbeVolume::update(std::uint64_t frame) {
  assert(cascadeCount_ > 0 && "uploadScene() first");
  // The previous update was waited for, so the host-visible volume struct is free to rewrite.
  const gpu_shared::ProbeVolume v = volumeParams(settings_, frame);
  std::memcpy(volume_.mapped(), &v, sizeof v);
  ProbeUpdatePushConstants trace = updatePushConstants(settings_, cascadeCount_, firstUpdate_);
  trace.counts.y = std::uint32_t(rayCount(settings_));
  ProbeUpdatePushConstants interior = trace;
  interior.counts.y = settings_.probeCount() * gpu_shared::kProbeBlendTexelsPerProbe;
  interior.mode.x = gpu_shared::kProbeBlendModeInterior;
  ProbeUpdatePushConstants border = trace;
  border.counts.y = settings_.probeCount() * gpu_shared::kProbeTileTexelsPerProbe;
  border.mode.x = gpu_shared::kProbeBlendModeBorder;

  gpu::CommandBatch batch = context_.beginBatch();
  batch.dispatch(
      "probe_trace", trace_,
      {&volume_, &irradiance_, &rays_, &pageTables_, &distance_, &albedo_, &emission_, &params_},
      &trace, sizeof trace, glm::uvec3(trace.counts.y, 1, 1));
  batch.dispatch("probe_blend", blend_, {&volume_, &irradiance_, &depth_, &rays_}, &interior,
                 sizeof interior, glm::uvec3(interior.counts.y, 1, 1));
  batch.dispatch("probe_border", blend_, {&volume_, &irradiance_, &depth_, &rays_}, &border,
                 sizeof border, glm::uvec3(border.counts.y, 1, 1));
  batch.submitAndWait();
  timings_ = batch.timings();
  firstUpdate_ = false;
}

std::vector<glm::vec3> ProbeVolume::sample(std::span<const gpu_shared::ProbeQuery> queries) {
  if (queries.empty()) return {};
  const std::size_t qBytes = queries.size() * sizeof(gpu_shared::ProbeQuery);
  const std::size_t rBytes = queries.size() * sizeof(glm::vec4);
  if (queries_.size() < qBytes) queries_ = gpu::Buffer(context_, qBytes, gpu::BufferKind::Upload);
  if (results_.size() < rBytes) results_ = gpu::Buffer(context_, rBytes, gpu::BufferKind::Readback);
  // Every earlier batch was waited for: the host-visible buffers are free to rewrite.
  std::memcpy(queries_.mapped(), queries.data(), qBytes);
  ProbeUpdatePushConstants pc = updatePushConstants(settings_, cascadeCount_, false);
  pc.counts.y = std::uint32_t(queries.size());
  gpu::CommandBatch batch = context_.beginBatch();
  batch.dispatch("probe_sample", sample_, {&volume_, &irradiance_, &depth_, &queries_, &results_},
                 &pc, sizeof pc, glm::uvec3(pc.counts.y, 1, 1));
  batch.submitAndWait();
  timings_ = batch.timings();
  std::vector<glm::vec3> out(queries.size());
  const auto* r = static_cast<const glm::vec4*>(results_.mapped());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = glm::vec3(r[i]);
  return out;
}

std::vector<glm::vec4> ProbeVolume::downloadIrradiance() const {
  std::vector<glm::vec4> out(irradianceTexelCount(settings_));
  irradiance_.download(out.data(), out.size() * sizeof(glm::vec4));
  return out;
}
std::vector<glm::vec2> ProbeVolume::downloadDepth() const {
  std::vector<glm::vec2> out(depthTexelCount(settings_));
  depth_.download(out.data(), out.size() * sizeof(glm::vec2));
  return out;
}
std::vector<glm::vec4> ProbeVolume::downloadRays() const {
  std::vector<glm::vec4> out(rayCount(settings_));
  rays_.download(out.data(), out.size() * sizeof(glm::vec4));
  return out;
}

}  // namespace sdfstream::probe
