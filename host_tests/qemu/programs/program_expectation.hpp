#pragma once
// What a program expects of the image it is linked with. One compiled main
// serves a pair of programs (the replay with the intact and with the flipped
// image; the cycle budget without and with a hysteresis block); each program
// links program_expectation.cpp compiled with its own definitions, so the
// pair shares the expensive object and still fails when its image is not
// the one it was meant to carry.

namespace cdcr::qemu_programs {

// The image is corrupted: the runtime must boot into DEGRADED.
extern const bool kExpectDegradedBoot;
// The image carries a hysteresis block: the runtime must track it.
extern const bool kExpectHysteresisBlock;
// The image has a compliance block: the runtime sags the nominal pose.
extern const bool kExpectComplianceBlock;
// The image's segments have three cables each (its cables block).
extern const bool kExpectThreeCables;

}  // namespace cdcr::qemu_programs
