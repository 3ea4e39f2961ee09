// Writes what the QEMU board programs are built from, into OUT_DIR:
//
//   cdcr_model_image.cpp          IMAGE as the exporter's C array, in .cdcr_model
//   cdcr_model_image_flipped.cpp  the same image with one byte flipped
//   cdcr_model_image_hysteresis.cpp  the same model with a hysteresis block
//                                 (two play operators per cable, widths 0.25
//                                 to 0.7 mm): the cycle budget with the
//                                 cables' hysteresis
//   cdcr_model_image_compliance.cpp  PAYLOAD_IMAGE (a payload model of the
//                                 same robot with a compliance block): the
//                                 cycle budget with the payload's sag
//   cdcr_model_image_three_cables.cpp  THREE_CABLE_IMAGE (a model of the
//                                 robot with three cables a segment): the
//                                 cycle budget of a three-cable robot
//   qemu_golden.hpp               cable inputs as they travel on the bus, and
//                                 the poses the host computes for them in
//                                 double: compensated with the image, and
//                                 nominal on the image's geometry (what a
//                                 board falls back to without a usable image),
//                                 and compensated with PAYLOAD_IMAGE, its
//                                 nominal pose sagged under its default payload
//
// The expected poses start from the image's float32 values widened to double
// and from the float cable lengths the runtime decodes, so the comparison on
// the target measures the float path alone.

#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "cdcr/firmware/protocol.hpp"
#include "cdcr/model/compensated_kinematics.hpp"
#include "cdcr/model/image_compliance.hpp"
#include "export/binary_file.hpp"
#include "export/c_source.hpp"
#include "export/image_writer.hpp"

namespace {

constexpr int kCases = 16;
// Inside the workspace the simulator samples by default, where the model
// was trained.
constexpr double kThetaMaxRad = 0.2;

using cdcr::model::Status;

void write_text(const std::string& path, const std::string& text) {
  std::ofstream file(path, std::ios::trunc);
  file << text;
  if (!file) throw std::runtime_error("cannot write " + path);
}

std::string exact(double value) {
  char text[40];
  std::snprintf(text, sizeof(text), "%.17g", value);
  return text;
}

std::string exact_float(float value) {
  char text[40];
  std::snprintf(text, sizeof(text), "%.9g", static_cast<double>(value));
  std::string literal = text;
  if (literal.find_first_of(".en") == std::string::npos) literal += ".0";
  return literal + "f";
}

void append_pose(const cdcr::model::Pose<double>& pose, std::ostringstream& position, std::ostringstream& rotation) {
  position << "    {" << exact(pose.position_mm[0]) << ", " << exact(pose.position_mm[1]) << ", "
           << exact(pose.position_mm[2]) << "},\n";
  rotation << "    {";
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) rotation << (r || c ? ", " : "") << exact(pose.rotation(r, c));
  }
  rotation << "},\n";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: make_qemu_golden IMAGE OUT_DIR PAYLOAD_IMAGE THREE_CABLE_IMAGE\n");
    return 2;
  }
  const std::string dir = argv[2];
  try {
    std::filesystem::create_directories(dir);
    std::vector<std::uint8_t> image = cdcr::exporting::read_binary_file(argv[1]);

    cdcr::model::ImageView view{};
    if (const auto s = cdcr::model::parse_image(image.data(), image.size(), view, cdcr::model::ImageCapacity{});
        s != cdcr::model::ImageStatus::ok) {
      throw std::runtime_error(std::string(argv[1]) + ": " + cdcr::model::to_string(s));
    }
    cdcr::model::RobotGeometry<double> geometry;
    if (cdcr::model::geometry_from_image(view, geometry) != Status::ok) throw std::runtime_error("bad geometry");
    cdcr::model::GpCorrection<double, double> correction;
    if (correction.bind(view) != Status::ok) throw std::runtime_error("cannot bind the image");
    const int segments = geometry.segment_count;

    std::mt19937 rng(20201109);
    std::uniform_real_distribution<double> alpha_rad(-3.1, 3.1);
    std::uniform_real_distribution<double> theta_rad(0.01, kThetaMaxRad);

    std::ostringstream cables_text, joints_text;
    std::ostringstream compensated_position, compensated_rotation, nominal_position, nominal_rotation;
    std::vector<cdcr::model::CableVector<double>> decoded_cables_mm;
    for (int c = 0; c < kCases; ++c) {
      cdcr::model::JointVector<double> joints(2 * segments);
      for (int s = 0; s < segments; ++s) {
        joints[2 * s] = alpha_rad(rng);
        joints[2 * s + 1] = theta_rad(rng);
      }
      cdcr::model::CableVector<double> cables_mm;
      if (cdcr::model::cables_from_joints(joints, geometry, cables_mm) != Status::ok) {
        throw std::runtime_error("cannot compute cable lengths");
      }
      // As the runtime sees them: through a feedback frame (0.01 mm quanta),
      // then float. The header keeps the decoded lengths, which the boards
      // encode again into the same frames.
      cables_text << "    {";
      for (int s = 0; s < segments; ++s) {
        const cdcr::firmware::protocol::CableFeedback sent{
            s, {cables_mm[4 * s], cables_mm[4 * s + 1], cables_mm[4 * s + 2], cables_mm[4 * s + 3]}};
        cdcr::firmware::protocol::CableFeedback received;
        cdcr::hal::CanFrame frame;
        if (!cdcr::firmware::protocol::encode(sent, frame) ||
            cdcr::firmware::protocol::decode(frame, received) != cdcr::firmware::protocol::DecodeStatus::ok) {
          throw std::runtime_error("a cable length beyond the feedback frame's range");
        }
        for (int k = 0; k < 4; ++k) {
          cables_text << (s || k ? ", " : "") << exact(received.lengths_mm[k]);
          cables_mm[4 * s + k] = static_cast<double>(static_cast<float>(received.lengths_mm[k]));
        }
      }
      cables_text << "},\n";
      decoded_cables_mm.push_back(cables_mm);

      cdcr::model::ForwardResult<double> result;
      if (cdcr::model::compensated_forward(cables_mm, geometry, correction, result) != Status::ok) {
        throw std::runtime_error("compensated_forward failed on a golden input");
      }
      append_pose(result.compensated, compensated_position, compensated_rotation);
      append_pose(result.nominal, nominal_position, nominal_rotation);
      joints_text << "    {";
      for (int k = 0; k < result.joints.size(); ++k) {
        joints_text << (k ? ", " : "") << exact_float(static_cast<float>(result.joints[k]));
      }
      joints_text << "},\n";
    }

    std::ostringstream geometry_text;
    for (int s = 0; s < segments; ++s) {
      const auto& g = geometry.segments[static_cast<std::size_t>(s)];
      geometry_text << "    {" << exact_float(static_cast<float>(g.backbone_length_mm)) << ", "
                    << exact_float(static_cast<float>(g.anchor_radius_mm)) << ", "
                    << exact_float(static_cast<float>(g.theta_max_rad)) << "},\n";
    }

    cdcr::exporting::CSourceOptions c_options;
    c_options.description = std::string("model for the QEMU board programs, from ") + argv[1];
    write_text(dir + "/cdcr_model_image.cpp", cdcr::exporting::format_c_source(image.data(), image.size(), c_options));
    // A hysteresis of the size the issue measured on a real robot (0.4 to
    // 0.7 mm at most per cable), fixed values: the image is reproducible.
    cdcr::model::HysteresisModel<double> hysteresis;
    hysteresis.cables = 4 * segments;
    hysteresis.operators = 2;
    for (int c = 0; c < hysteresis.cables; ++c) {
      hysteresis.widths_mm[c][0] = 0.25 + 0.01 * (c % 7);
      hysteresis.widths_mm[c][1] = 0.6 + 0.01 * (c % 5);
      hysteresis.weights[c][0] = 0.5;
      hysteresis.weights[c][1] = 0.4;
    }
    cdcr::model::CableVector<double> approach_mm, home_mm;
    if (cdcr::model::homing_waypoints(geometry, approach_mm, home_mm) != Status::ok) {
      throw std::runtime_error("no homing move for the image's geometry");
    }
    cdcr::model::compute_homing_lags(hysteresis, approach_mm, home_mm);
    const std::vector<std::uint8_t> with_hysteresis = cdcr::exporting::with_hysteresis_block(image, hysteresis);
    c_options.description = "the same model with a hysteresis block of two play operators per cable";
    write_text(dir + "/cdcr_model_image_hysteresis.cpp",
               cdcr::exporting::format_c_source(with_hysteresis.data(), with_hysteresis.size(), c_options));

    const std::vector<std::uint8_t> payload_image = cdcr::exporting::read_binary_file(argv[3]);
    cdcr::model::ImageView payload_view{};
    if (const auto s = cdcr::model::parse_image(payload_image.data(), payload_image.size(), payload_view,
                                                cdcr::model::ImageCapacity{});
        s != cdcr::model::ImageStatus::ok) {
      throw std::runtime_error(std::string(argv[3]) + ": " + cdcr::model::to_string(s));
    }
    if (payload_view.compliance_segments != segments) {
      throw std::runtime_error(std::string(argv[3]) + ": no compliance block for the image's " +
                               std::to_string(segments) + " segments (cdcr train chose no sag)");
    }
    cdcr::model::RobotGeometry<double> payload_geometry;
    cdcr::model::GpCorrection<double, double> payload_correction;
    cdcr::model::PayloadCompliance<double> compliance;
    if (cdcr::model::geometry_from_image(payload_view, payload_geometry) != Status::ok ||
        payload_correction.bind(payload_view) != Status::ok ||
        !cdcr::model::compliance_from_image(payload_view, compliance)) {
      throw std::runtime_error(std::string("cannot bind ") + argv[3]);
    }
    // A payload of zero would leave the payload's own sag unchecked.
    if (!(payload_correction.payload_kg() > 0.0)) throw std::runtime_error(std::string(argv[3]) + ": no default payload");
    std::ostringstream sagged_position, sagged_rotation;
    for (const cdcr::model::CableVector<double>& cables_mm : decoded_cables_mm) {
      cdcr::model::ForwardResult<double> result;
      if (cdcr::model::compensated_forward(cables_mm, payload_geometry, payload_correction, compliance, result) !=
          Status::ok) {
        throw std::runtime_error("the payload model's compensated_forward failed on a golden input");
      }
      append_pose(result.compensated, sagged_position, sagged_rotation);
    }
    c_options.description = std::string("a payload model with a compliance block, from ") + argv[3];
    write_text(dir + "/cdcr_model_image_compliance.cpp",
               cdcr::exporting::format_c_source(payload_image.data(), payload_image.size(), c_options));

    const std::vector<std::uint8_t> three_cable_image = cdcr::exporting::read_binary_file(argv[4]);
    cdcr::model::ImageView three_cable_view{};
    if (const auto s = cdcr::model::parse_image(three_cable_image.data(), three_cable_image.size(), three_cable_view,
                                                cdcr::model::ImageCapacity{});
        s != cdcr::model::ImageStatus::ok) {
      throw std::runtime_error(std::string(argv[4]) + ": " + cdcr::model::to_string(s));
    }
    if (three_cable_view.cable_count != 3 * three_cable_view.segment_count) {
      throw std::runtime_error(std::string(argv[4]) + ": not three cables a segment");
    }
    c_options.description = std::string("a model of the robot with three cables a segment, from ") + argv[4];
    write_text(dir + "/cdcr_model_image_three_cables.cpp",
               cdcr::exporting::format_c_source(three_cable_image.data(), three_cable_image.size(), c_options));

    // In the middle of the training data: only the CRC can tell.
    image[image.size() / 2] ^= 0xFF;
    c_options.description = "the same model with one byte flipped";
    write_text(dir + "/cdcr_model_image_flipped.cpp",
               cdcr::exporting::format_c_source(image.data(), image.size(), c_options));

    std::ostringstream header;
    header << "#pragma once\n"
           << "// Generated by make_qemu_golden from " << argv[1] << ": inputs and host (double)\n"
           << "// results for the image in cdcr_model_image.cpp.\n\n"
           << "#include <cstdint>\n\n"
           << "namespace cdcr::qemu_golden {\n\n"
           << "inline constexpr int kSegments = " << segments << ";\n"
           << "inline constexpr int kCases = " << kCases << ";\n"
           << "inline constexpr std::uint32_t kTrainingPoints = " << view.training_points << ";\n\n"
           << "// The image's geometry: backbone length (mm), anchor radius (mm), theta max (rad).\n"
           << "inline constexpr float kGeometry[kSegments][3] = {\n" << geometry_text.str() << "};\n\n"
           << "// Cable lengths (mm) as decoded from the feedback frames, segment by segment.\n"
           << "inline constexpr double kCablesMm[kCases][4 * kSegments] = {\n" << cables_text.str() << "};\n\n"
           << "// (alpha, theta) per segment for the cables above.\n"
           << "inline constexpr float kJoints[kCases][2 * kSegments] = {\n" << joints_text.str() << "};\n\n"
           << "inline constexpr double kCompensatedPositionMm[kCases][3] = {\n" << compensated_position.str() << "};\n\n"
           << "// Row-major.\n"
           << "inline constexpr double kCompensatedRotation[kCases][9] = {\n" << compensated_rotation.str() << "};\n\n"
           << "inline constexpr double kNominalPositionMm[kCases][3] = {\n" << nominal_position.str() << "};\n\n"
           << "inline constexpr double kNominalRotation[kCases][9] = {\n" << nominal_rotation.str() << "};\n\n"
           << "// The payload model of cdcr_model_image_compliance.cpp at the same cables: compensated,\n"
           << "// its nominal pose sagged under the image's default payload.\n"
           << "inline constexpr double kPayloadKg = " << exact(payload_correction.payload_kg()) << ";\n\n"
           << "inline constexpr double kSaggedPositionMm[kCases][3] = {\n" << sagged_position.str() << "};\n\n"
           << "// Row-major.\n"
           << "inline constexpr double kSaggedRotation[kCases][9] = {\n" << sagged_rotation.str() << "};\n\n"
           << "}  // namespace cdcr::qemu_golden\n";
    write_text(dir + "/qemu_golden.hpp", header.str());
  } catch (const std::exception& error) {
    std::fprintf(stderr, "make_qemu_golden: %s\n", error.what());
    return 1;
  }
  return 0;
}
