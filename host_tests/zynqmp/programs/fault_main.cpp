// The board's exception path, one fault per program (zynqmp.fault_report,
// zynqmp.mpu_fault_report): the fault must reach the vector table, run its
// handler on its mode's stack, report on the UART and end QEMU with the
// hard-fault status (3), instead of hanging or passing.
//   CDCR_FAULT_UNDEFINED  an undefined instruction
//   CDCR_FAULT_MPU        a read of the OCM, which QEMU maps but the MPU
//                         regions leave out: a data abort only while the MPU
//                         is on

#include <cstdint>

#include <cdcr/zynqmp/console.hpp>

int main() {
#if CDCR_FAULT_UNDEFINED
  cdcr::zynqmp::console_write("zynqmp fault report: executing an undefined instruction\n");
  // The architecturally undefined encoding (UDF) in Thumb state, where
  // main runs.
  asm volatile("udf #0" ::: "memory");
#elif CDCR_FAULT_MPU
  cdcr::zynqmp::console_write("zynqmp fault report: reading the OCM, outside every MPU region\n");
  constexpr std::uintptr_t kOcmBase = 0xFFFC0000u;
  const std::uint32_t value = *reinterpret_cast<volatile const std::uint32_t*>(kOcmBase);
  cdcr::zynqmp::console_write_hex(value);
  cdcr::zynqmp::console_write(" read: the MPU let it through\n");
#else
#error "define CDCR_FAULT_UNDEFINED or CDCR_FAULT_MPU"
#endif
  cdcr::zynqmp::console_write("PASS\n");  // never reached: the test fails on it
  return 0;
}
