#pragma once
// The STATS frame's FAULT_DETAIL: one byte whose meaning depends on the FAULT
// that STATUS reports with it, so the value records which enum it carries and
// can be built only from those enums.
//
//   FAULT                                      FAULT_DETAIL
//   image_invalid                              model::ImageStatus (the parser's verdict)
//   image_geometry_invalid,                    model::Status
//   cable_lengths_invalid, target_unreachable
//   drive_silent, drive_fault, drive_refused   the drive's node id (0: the configuration as given)
//   every other code                           nothing (0)

#include <cstdint>

#include "cdcr/firmware/fault.hpp"
#include "cdcr/model/flash_image.hpp"
#include "cdcr/model/status.hpp"

namespace cdcr::firmware {

enum class FaultDetailKind : std::uint8_t { none, image_status, model_status, drive_node };

// Which enum details a fault code (the table above).
constexpr FaultDetailKind detail_kind(FaultCode code) {
  switch (code) {
    case FaultCode::image_invalid:
      return FaultDetailKind::image_status;
    case FaultCode::image_geometry_invalid:
    case FaultCode::cable_lengths_invalid:
    case FaultCode::target_unreachable:
      return FaultDetailKind::model_status;
    case FaultCode::drive_silent:
    case FaultCode::drive_fault:
    case FaultCode::drive_refused:
      return FaultDetailKind::drive_node;
    case FaultCode::none:
    case FaultCode::image_missing:
    case FaultCode::cable_input_stale:
    case FaultCode::cable_frame_malformed:
    case FaultCode::target_malformed:
    case FaultCode::can_transmit_failed:
    case FaultCode::can_filters_refused:
    case FaultCode::payload_invalid:
    case FaultCode::homing_malformed:
    case FaultCode::drives_command_malformed:
      return FaultDetailKind::none;
  }
  return FaultDetailKind::none;
}

class FaultDetail {
 public:
  constexpr FaultDetail() = default;  // no detail
  constexpr explicit FaultDetail(model::ImageStatus status)
      : kind_(FaultDetailKind::image_status), value_(static_cast<std::uint8_t>(status)) {}
  constexpr explicit FaultDetail(model::Status status)
      : kind_(FaultDetailKind::model_status), value_(static_cast<std::uint8_t>(status)) {}
  static constexpr FaultDetail drive(std::uint8_t node) { return FaultDetail(FaultDetailKind::drive_node, node); }

  // The byte a receiver read, typed by the FAULT code it came with.
  static constexpr FaultDetail from_wire(FaultCode fault, std::uint8_t byte) {
    switch (detail_kind(fault)) {
      case FaultDetailKind::image_status: return FaultDetail(static_cast<model::ImageStatus>(byte));
      case FaultDetailKind::model_status: return FaultDetail(static_cast<model::Status>(byte));
      case FaultDetailKind::drive_node: return drive(byte);
      case FaultDetailKind::none: break;
    }
    return FaultDetail();
  }

  constexpr FaultDetailKind kind() const { return kind_; }
  constexpr std::uint8_t wire_value() const { return value_; }
  // Whether this is the detail `code` is documented to carry.
  constexpr bool details(FaultCode code) const { return kind_ == detail_kind(code); }
  // Meaningful only for the matching kind(); ok otherwise.
  constexpr model::ImageStatus image_status() const {
    return kind_ == FaultDetailKind::image_status ? static_cast<model::ImageStatus>(value_) : model::ImageStatus::ok;
  }
  constexpr model::Status model_status() const {
    return kind_ == FaultDetailKind::model_status ? static_cast<model::Status>(value_) : model::Status::ok;
  }
  constexpr std::uint8_t drive_node() const { return kind_ == FaultDetailKind::drive_node ? value_ : 0; }

  friend constexpr bool operator==(FaultDetail a, FaultDetail b) { return a.kind_ == b.kind_ && a.value_ == b.value_; }
  friend constexpr bool operator!=(FaultDetail a, FaultDetail b) { return !(a == b); }

 private:
  constexpr FaultDetail(FaultDetailKind kind, std::uint8_t value) : kind_(kind), value_(value) {}

  FaultDetailKind kind_ = FaultDetailKind::none;
  std::uint8_t value_ = 0;
};

}  // namespace cdcr::firmware
