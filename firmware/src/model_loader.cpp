#include "cdcr/firmware/model_loader.hpp"

#include "cdcr/model/image_compliance.hpp"

namespace cdcr::firmware {

namespace {

// A slot's image with the checks scanned when it was hashed: the switch to
// it reads no whole image in its cycle.
model::ImageStatus parse_model(const SlotImage& source, model::ImageView& view) {
  model::ImageCapacity capacity;
  capacity.max_training_points = kMaxTrainingPoints;
  capacity.max_segments = kMaxSegments;
  capacity.max_variance_rank = kMaxVarianceRank;
  const hal::MemoryRegion& region = source.region;
  if (source.scan.done()) return model::parse_image(region.data, region.size_bytes, view, capacity, source.scan);
  return model::parse_image(region.data, region.size_bytes, view, capacity);
}

bool image_loads(const SlotImage& source, RobotModel& model) {
  if (source.region.data == nullptr || source.region.size_bytes == 0) return false;
  model::ImageView view;
  Geometry geometry;
  return parse_model(source, view) == model::ImageStatus::ok &&
         model::geometry_from_image(view, geometry) == model::Status::ok &&
         geometry.validate() == model::Status::ok && model.correction.bind(view) == model::Status::ok &&
         model.uncertainty.bind(view) == model::Status::ok;
}

SlotImage model_source(ModelUpdate& update, const hal::ModelStorage& storage, RobotModel& model) {
  if (!update.booted()) update.boot();
  for (int i = 0; i < update.candidate_count(); ++i) {
    if (image_loads(update.candidate(i), model)) {
      update.set_active(i);
      return update.candidate(i);
    }
  }
  update.set_active(-1);
  SlotImage source;
  source.region = storage.model_region();
  return source;
}

}  // namespace

BootFault load_model(ModelUpdate& update, const hal::ModelStorage& storage, const Geometry& fallback,
                     RobotModel& model) {
  BootFault fault;
  const SlotImage source = model_source(update, storage, model);
  model.geometry = fallback;
  model.compliance = Compliance{};
  if (source.region.data == nullptr || source.region.size_bytes == 0) {
    fault.code = FaultCode::image_missing;
    return fault;
  }
  const model::ImageStatus parsed = parse_model(source, model.image);
  if (parsed != model::ImageStatus::ok) {
    fault.code = FaultCode::image_invalid;
    fault.detail = FaultDetail(parsed);
    return fault;
  }
  model::Status status = model::geometry_from_image(model.image, model.geometry);
  if (status == model::Status::ok) status = model.correction.bind(model.image);
  if (status == model::Status::ok) status = model.uncertainty.bind(model.image);
  if (status == model::Status::ok) model::compliance_from_image(model.image, model.compliance);
  if (status != model::Status::ok) {
    model.geometry = fallback;
    fault.code = FaultCode::image_geometry_invalid;
    fault.detail = FaultDetail(status);
  }
  return fault;
}

}  // namespace cdcr::firmware
