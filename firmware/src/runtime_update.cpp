// The runtime's side of model updates: which image init() loads (the newest
// committed slot that loads, else the model storage's image), and the
// switch to a new image once it is committed.

#include "cdcr/firmware/runtime.hpp"

namespace cdcr::firmware {

// A slot's image with the checks scanned when it was hashed: the switch to
// it reads no whole image in its cycle.
model::ImageStatus Runtime::parse_model(const SlotImage& source, model::ImageView& view) const {
  model::ImageCapacity capacity;
  capacity.max_training_points = kMaxTrainingPoints;
  capacity.max_segments = kMaxSegments;
  capacity.max_variance_rank = kMaxVarianceRank;
  const hal::MemoryRegion& region = source.region;
  if (source.scan.done()) return model::parse_image(region.data, region.size_bytes, view, capacity, source.scan);
  return model::parse_image(region.data, region.size_bytes, view, capacity);
}

bool Runtime::image_loads(const SlotImage& source) {
  if (source.region.data == nullptr || source.region.size_bytes == 0) return false;
  model::ImageView view;
  Geometry geometry;
  return parse_model(source, view) == model::ImageStatus::ok &&
         model::geometry_from_image(view, geometry) == model::Status::ok &&
         geometry.validate() == model::Status::ok && correction_.bind(view) == model::Status::ok &&
         uncertainty_.bind(view) == model::Status::ok;
}

SlotImage Runtime::model_source() {
  if (!update_.booted()) update_.boot();
  for (int i = 0; i < update_.candidate_count(); ++i) {
    if (image_loads(update_.candidate(i))) {
      update_.set_active(i);
      return update_.candidate(i);
    }
  }
  update_.set_active(-1);
  SlotImage storage;
  storage.region = hal_.model_storage.model_region();
  return storage;
}

// Between two cycles' work: the request being solved was for the old
// model, and the variance in progress too. The cables received so far stay.
void Runtime::reload_model() {
  if (solving_) end_solve(protocol::IkOutcome::superseded);
  uncertainty_running_ = false;
  const Cables cables_mm = latest_cables_mm_;
  const int segments = geometry_.segment_count;
  init();
  if (geometry_.segment_count == segments) latest_cables_mm_ = cables_mm;
}

}  // namespace cdcr::firmware
