#include "view/view_channels.hpp"

#include <nlohmann/json.hpp>

namespace cdcr::view {

namespace {

using nlohmann::json;

json typed(const char* type) { return json{{"type", type}}; }
json object(const char* title, json properties) {
  return json{{"title", title}, {"type", "object"}, {"properties", std::move(properties)}};
}
json array_of(json items) { return json{{"type", "array"}, {"items", std::move(items)}}; }
json numbers() { return array_of(typed("number")); }

json time_schema() { return object("time", {{"sec", typed("integer")}, {"nsec", typed("integer")}}); }
json vector3(const char* title) {
  return object(title, {{"x", typed("number")}, {"y", typed("number")}, {"z", typed("number")}});
}
json quaternion() {
  return object("foxglove.Quaternion",
                {{"x", typed("number")}, {"y", typed("number")}, {"z", typed("number")}, {"w", typed("number")}});
}
json pose() { return object("foxglove.Pose", {{"position", vector3("foxglove.Vector3")}, {"orientation", quaternion()}}); }
json color() {
  return object("foxglove.Color",
                {{"r", typed("number")}, {"g", typed("number")}, {"b", typed("number")}, {"a", typed("number")}});
}

json scene_update() {
  const json sphere = object("foxglove.SpherePrimitive",
                             {{"pose", pose()}, {"size", vector3("foxglove.Vector3")}, {"color", color()}});
  const json line = object("foxglove.LinePrimitive", {{"type", typed("integer")},
                                                      {"pose", pose()},
                                                      {"thickness", typed("number")},
                                                      {"scale_invariant", typed("boolean")},
                                                      {"points", array_of(vector3("foxglove.Point3"))},
                                                      {"color", color()},
                                                      {"colors", array_of(color())},
                                                      {"indices", array_of(typed("integer"))}});
  const json arrow = object("foxglove.ArrowPrimitive", {{"pose", pose()},
                                                        {"shaft_length", typed("number")},
                                                        {"shaft_diameter", typed("number")},
                                                        {"head_length", typed("number")},
                                                        {"head_diameter", typed("number")},
                                                        {"color", color()}});
  const json text = object("foxglove.TextPrimitive", {{"pose", pose()},
                                                      {"billboard", typed("boolean")},
                                                      {"font_size", typed("number")},
                                                      {"scale_invariant", typed("boolean")},
                                                      {"color", color()},
                                                      {"text", typed("string")}});
  const json entity = object("foxglove.SceneEntity", {{"timestamp", time_schema()},
                                                      {"frame_id", typed("string")},
                                                      {"id", typed("string")},
                                                      {"lifetime", object("duration", {{"sec", typed("integer")},
                                                                                       {"nsec", typed("integer")}})},
                                                      {"frame_locked", typed("boolean")},
                                                      {"metadata", typed("array")},
                                                      {"arrows", array_of(arrow)},
                                                      {"cubes", typed("array")},
                                                      {"spheres", array_of(sphere)},
                                                      {"cylinders", typed("array")},
                                                      {"lines", array_of(line)},
                                                      {"triangles", typed("array")},
                                                      {"texts", array_of(text)},
                                                      {"models", typed("array")}});
  return object("foxglove.SceneUpdate", {{"deletions", typed("array")}, {"entities", array_of(entity)}});
}

json frame_transforms() {
  const json transform = object("foxglove.FrameTransform", {{"timestamp", time_schema()},
                                                            {"parent_frame_id", typed("string")},
                                                            {"child_frame_id", typed("string")},
                                                            {"translation", vector3("foxglove.Vector3")},
                                                            {"rotation", quaternion()}});
  return object("foxglove.FrameTransforms", {{"transforms", array_of(transform)}});
}

json pose_in_frame() {
  return object("foxglove.PoseInFrame", {{"timestamp", time_schema()}, {"frame_id", typed("string")}, {"pose", pose()}});
}

json tip_uncertainty() {
  return object("cdcr.TipUncertainty", {{"timestamp", time_schema()},
                                        {"r95_mm", typed("number")},
                                        {"r95_deg", typed("number")},
                                        {"extrapolating", typed("boolean")},
                                        {"outside_range", typed("boolean")},
                                        {"compensated", typed("boolean")}});
}

json cables() {
  return object("cdcr.Cables", {{"timestamp", time_schema()},
                                {"feedback_mm", numbers()},
                                {"setpoints_mm", numbers()},
                                {"has_setpoints", typed("boolean")}});
}

json following_error() {
  return object("cdcr.FollowingError",
                {{"timestamp", time_schema()}, {"cables_mm", numbers()}, {"largest_mm", typed("number")}});
}

json status() {
  return object("cdcr.Status", {{"timestamp", time_schema()},
                                {"state", typed("string")},
                                {"fault", typed("string")},
                                {"fault_code", typed("integer")},
                                {"overruns", typed("integer")},
                                {"exec_max_us", typed("integer")},
                                {"exec_mean_us", typed("integer")},
                                {"extrapolating", typed("boolean")},
                                {"hysteresis_unknown", typed("boolean")}});
}

json ik_report() {
  return object("cdcr.IkReport", {{"timestamp", time_schema()},
                                  {"sequence", typed("integer")},
                                  {"outcome", typed("string")},
                                  {"iterations", typed("integer")},
                                  {"cycles", typed("integer")},
                                  {"position_residual_mm", typed("number")},
                                  {"orientation_residual_rad", typed("number")}});
}

}  // namespace

const std::array<ChannelDescription, kTopicCount>& view_channels() {
  static const std::array<ChannelDescription, kTopicCount> channels{{
      {"/scene", "foxglove.SceneUpdate", scene_update().dump()},
      {"/tf", "foxglove.FrameTransforms", frame_transforms().dump()},
      {"/tip/pose", "foxglove.PoseInFrame", pose_in_frame().dump()},
      {"/tip/nominal_pose", "foxglove.PoseInFrame", pose_in_frame().dump()},
      {"/tip/uncertainty", "cdcr.TipUncertainty", tip_uncertainty().dump()},
      {"/target", "foxglove.PoseInFrame", pose_in_frame().dump()},
      {"/cables", "cdcr.Cables", cables().dump()},
      {"/cables/following_error", "cdcr.FollowingError", following_error().dump()},
      {"/status", "cdcr.Status", status().dump()},
      {"/ik_report", "cdcr.IkReport", ik_report().dump()},
  }};
  return channels;
}

}  // namespace cdcr::view
