#include "program_expectation.hpp"

#ifndef CDCR_EXPECT_DEGRADED_BOOT
#error "CDCR_EXPECT_DEGRADED_BOOT must be defined by the program's build (0 or 1)"
#endif
#ifndef CDCR_EXPECT_HYSTERESIS_BLOCK
#error "CDCR_EXPECT_HYSTERESIS_BLOCK must be defined by the program's build (0 or 1)"
#endif
#ifndef CDCR_EXPECT_COMPLIANCE_BLOCK
#error "CDCR_EXPECT_COMPLIANCE_BLOCK must be defined by the program's build (0 or 1)"
#endif
#ifndef CDCR_EXPECT_THREE_CABLES
#error "CDCR_EXPECT_THREE_CABLES must be defined by the program's build (0 or 1)"
#endif

namespace cdcr::qemu_programs {

const bool kExpectDegradedBoot = CDCR_EXPECT_DEGRADED_BOOT != 0;
const bool kExpectHysteresisBlock = CDCR_EXPECT_HYSTERESIS_BLOCK != 0;
const bool kExpectComplianceBlock = CDCR_EXPECT_COMPLIANCE_BLOCK != 0;
const bool kExpectThreeCables = CDCR_EXPECT_THREE_CABLES != 0;

}  // namespace cdcr::qemu_programs
