#pragma once
// Which image the runtime runs, at boot and after a model update: the newest
// committed slot whose image loads, else the model storage's image; bound
// into the runtime's model, or the fallback geometry alone and the boot fault
// that says why.

#include "cdcr/firmware/fault.hpp"
#include "cdcr/firmware/fault_detail.hpp"
#include "cdcr/firmware/kinematics.hpp"
#include "cdcr/firmware/model_update.hpp"
#include "cdcr/hal/model_storage.hpp"

namespace cdcr::firmware {

struct BootFault {
  FaultCode code = FaultCode::none;
  FaultDetail detail;
};

// Binds `model` (geometry, image, correction, variance block); tells the
// update which slot is now active. `model.compensated` is left alone.
BootFault load_model(ModelUpdate& update, const hal::ModelStorage& storage, const Geometry& fallback,
                     RobotModel& model);

}  // namespace cdcr::firmware
