// The payload's sag on the board: model::sagged_bends and its inverse
// instantiated once, out of line, for the forward path, the IK's correction
// and the setpoints alike. (At -Os the sag takes four times the
// instructions, 81,795 on the Cortex-M7, for no code saved: measured.)
#include "cdcr/firmware/kinematics.hpp"
#include "cdcr/model/payload_compliance.hpp"

namespace cdcr::firmware {

Joints sagged_bends_of(const Compliance& compliance, const Geometry& geometry, Scalar payload_kg, const Joints& bend) {
  return model::sagged_bends(bend, geometry, payload_kg, compliance);
}

Joints commanded_bends_of(const Compliance& compliance, const Geometry& geometry, Scalar payload_kg,
                          const Joints& sagged) {
  return model::commanded_bends(sagged, geometry, payload_kg, compliance);
}

Joints commanded_joints(const RobotModel& model, const Joints& solver_joints) {
  if (!model.compensated || model.compliance.empty()) return solver_joints;
  return model::joints_from_bend(commanded_bends_of(model.compliance, model.geometry, model.correction.payload_kg(),
                                                    model::bend_from_joints(solver_joints)));
}

}  // namespace cdcr::firmware
