// The public Filter: creation, parameters, submit and timings, over Filter::Impl (filter_impl.h).
#include "steadyxr/core/filter.h"

#include <map>
#include <string>
#include <tuple>

#include "filter_impl.h"

namespace steadyxr::core {

Filter::Filter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Filter::~Filter() = default;

std::unique_ptr<Filter> Filter::create(VulkanContext& context, const Params& params, std::string* error,
                                       const FilterOptions& options) {
  Params p;
  if (std::string msg = validate(params, &p); !msg.empty()) {
    if (error) *error = msg;
    return nullptr;
  }
  detail::PipelineStore* store = context.pipelineStore(error);
  if (!store) return nullptr;
  auto impl = std::make_unique<Impl>(context, *store, options);
  impl->params = p;
  impl->pendingParams = p;
  if (!impl->init(error)) return nullptr;
  return std::unique_ptr<Filter>(new Filter(std::move(impl)));
}

bool Filter::compiling() const {
  return impl_->pipelines.compiling;
}

bool Filter::submit(const StereoFrame& frame, const StereoOutput& output, std::string* error,
                    VkSemaphore signalSemaphore) {
  if (error) error->clear();
  return impl_->submit(frame, output, error, signalSemaphore);
}

void Filter::setParams(const Params& params) {
  validate(params, &impl_->pendingParams);  // bad fields fall back to their defaults
  impl_->paramsChanged = true;
}

const Params& Filter::params() const {
  return impl_->paramsChanged ? impl_->pendingParams : impl_->params;
}
void Filter::reset() {
  impl_->resetRequested = true;
}
void Filter::setDepthMayChange(bool mayChange) {
  impl_->depthMayChange = mayChange;
}
void Filter::waitIdle() {
  impl_->waitAll();
}
std::optional<PassTimings> Filter::lastTimings() const {
  return impl_->timings;
}
std::optional<float> Filter::estimatedNoiseVariance() const {
  return impl_->noiseTracker.variance();
}

std::optional<GainProbeSums> Filter::lastGainProbe() const {
  return impl_->gainProbe;
}

std::optional<HeadLockedEvidence> Filter::headLockedEvidence() const {
  return impl_->headLocked.evidence();
}

RenderSizeCounters Filter::renderSizeCounters() const {
  return impl_->sizeCounters;
}

uint64_t Filter::imageMemoryBytes() const {
  uint64_t bytes = 0;
  for (const detail::EyeState& eye : impl_->eyes) {
    for (const auto* images : {&eye.history, &eye.scratch, &eye.shown})
      for (const detail::OwnedImage& img : *images) bytes += img.bytes;
    bytes += eye.headLockedRecord.bytes;
  }
  return bytes;
}

std::vector<PipelineDescription> Filter::pipelines() const {
  return impl_->pipelines.made();
}

void Filter::forgetImage(VkImage image) {
  bool any = false;
  for (const auto& [key, v] : impl_->views) any = any || std::get<0>(key) == image;
  if (!any) return;
  impl_->waitAll();  // a pending frame may still use the view
  std::erase_if(impl_->views, [&](const auto& kv) { return std::get<0>(kv.first) == image; });
}

}  // namespace steadyxr::core
