#pragma once
// The channels of the view (the live Foxglove WebSocket server and the MCAP
// recordings carry the same ones), each with its JSON schema. The scene,
// frames and poses are Foxglove's own message types (foxglove.SceneUpdate,
// foxglove.FrameTransforms, foxglove.PoseInFrame: the 3D panel draws them),
// in metres as Foxglove's types are; the project's readings (cdcr.*) keep
// the protocol's units, named in every field. A schema lists the fields the
// view sends, with their types: host_tests/tools/view checks each against
// the schema of the same name in @foxglove/schemas.

#include <array>
#include <string>

namespace cdcr::view {

enum class Topic : int {
  scene,             // /scene: the backbone, the tip, the r95 sphere, the target
  transforms,        // /tf: base -> tip, nominal tip and target frames
  tip_pose,          // /tip/pose: the compensated tip
  nominal_tip_pose,  // /tip/nominal_pose: the nominal model's tip
  tip_uncertainty,   // /tip/uncertainty: r95 radii and the extrapolation flag
  target,            // /target: the latest committed target
  cables,            // /cables: feedback and setpoints, mm
  following_error,   // /cables/following_error: setpoint - feedback, mm
  status,            // /status: STATUS as decoded
  ik_report,         // /ik_report: IK_REPORT as decoded
};
inline constexpr int kTopicCount = 10;

struct ChannelDescription {
  const char* topic;
  const char* schema_name;
  std::string schema;  // JSON schema text
};

const std::array<ChannelDescription, kTopicCount>& view_channels();

inline const ChannelDescription& channel(Topic topic) { return view_channels()[static_cast<int>(topic)]; }

}  // namespace cdcr::view
