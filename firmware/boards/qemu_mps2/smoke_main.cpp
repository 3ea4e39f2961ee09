// Boot check for QEMU's MPS2 boards: parses the model image linked into
// .cdcr_model with the shared parser, runs the float compensated forward path
// on golden cable inputs and compares the poses with the host's double
// results. Prints PASS or FAIL and exits with the status over semihosting.

#include <cmath>
#include <cstdint>

#include "cdcr/cortexm/semihosting.hpp"
#include "cdcr/model/compensated_kinematics.hpp"
#include "qemu_golden.hpp"

extern "C" {
extern const std::uint8_t cdcr_model_image[];
extern const std::uint32_t cdcr_model_image_size;
}

namespace {

namespace console = cdcr::cortexm;
namespace golden = cdcr::qemu_golden;
using namespace cdcr::model;

constexpr double kPositionToleranceMm = 0.01;
constexpr double kOrientationToleranceDeg = 0.001;
constexpr double kDegPerRad = 57.295779513082320876;

// The six sums are where float loses digits first: double costs nothing extra
// on an FPU with double support (Cortex-M7), a compensated float sum serves
// single-precision FPUs (Cortex-M4F).
#if defined(__ARM_FP) && (__ARM_FP & 0x8)
using Accumulator = double;
constexpr const char* kAccumulatorName = "double";
#else
using Accumulator = CompensatedFloat;
constexpr const char* kAccumulatorName = "compensated float";
#endif

// Static rather than on the stack: the forward path's fixed-capacity
// matrices are sized for eight segments.
GpCorrection<float, Accumulator> correction;
RobotGeometry<float> geometry;
ForwardResult<float> result;

bool fail(const char* what) {
  console::console_write("FAIL: ");
  console::console_write(what);
  console::console_write("\n");
  return false;
}

bool check_case(int c) {
  CableVector<float> cables_mm(4 * golden::kSegments);
  for (int k = 0; k < cables_mm.size(); ++k) cables_mm[k] = golden::kCablesMm[c][k];
  if (compensated_forward(cables_mm, geometry, correction, result) != Status::ok) {
    return fail("compensated_forward rejected a golden input");
  }

  double position_error_sq_mm = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double d = static_cast<double>(result.compensated.position_mm[i]) - golden::kPositionMm[c][i];
    position_error_sq_mm += d * d;
  }
  const double position_error_mm = std::sqrt(position_error_sq_mm);
  // Angle of M = R_expected^T R from atan2(|skew part|, (trace - 1) / 2):
  // acos of the trace alone would read float rounding in R (not quite
  // orthonormal) as hundredths of a degree.
  double m[3][3];
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      m[i][j] = 0.0;
      for (int k = 0; k < 3; ++k) {
        m[i][j] += golden::kRotation[c][3 * k + i] * static_cast<double>(result.compensated.rotation(k, j));
      }
    }
  }
  const double wx = 0.5 * (m[2][1] - m[1][2]);
  const double wy = 0.5 * (m[0][2] - m[2][0]);
  const double wz = 0.5 * (m[1][0] - m[0][1]);
  const double sin_angle = std::sqrt(wx * wx + wy * wy + wz * wz);
  const double cos_angle = 0.5 * (m[0][0] + m[1][1] + m[2][2] - 1.0);
  const double orientation_error_deg = std::atan2(sin_angle, cos_angle) * kDegPerRad;

  console::console_write("case ");
  console::console_write_int(c);
  console::console_write(": position error ");
  console::console_write_fixed(position_error_mm, 6);
  console::console_write(" mm, orientation error ");
  console::console_write_fixed(orientation_error_deg, 6);
  console::console_write(" deg\n");
  if (!(position_error_mm <= kPositionToleranceMm)) return fail("position beyond tolerance");
  if (!(orientation_error_deg <= kOrientationToleranceDeg)) return fail("orientation beyond tolerance");
  return true;
}

}  // namespace

int main() {
  console::console_write("cdcr QEMU smoke test (");
  console::console_write(kAccumulatorName);
  console::console_write(" accumulation)\n");

  ImageView view{};
  const ImageStatus image_status = parse_image(cdcr_model_image, cdcr_model_image_size, view, ImageCapacity{});
  if (image_status != ImageStatus::ok) {
    console::console_write("FAIL: ");
    console::console_write(to_string(image_status));
    console::console_write("\n");
    return 1;
  }
  if (geometry_from_image(view, geometry) != Status::ok) return fail("image geometry rejected"), 1;
  if (view.segment_count != golden::kSegments) return fail("image and golden data disagree on segments"), 1;
  if (correction.bind(view) != Status::ok) return fail("cannot bind the image"), 1;

  bool passed = true;
  for (int c = 0; c < golden::kCases; ++c) passed = check_case(c) && passed;
  console::console_write(passed ? "PASS\n" : "FAIL\n");
  return passed ? 0 : 1;
}
