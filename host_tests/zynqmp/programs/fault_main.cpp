// The board's exception path (zynqmp.fault_report): an undefined instruction
// must reach the vector table, run its handler on the Undefined mode's stack,
// report on the UART and end QEMU with the hard-fault status (3), instead of
// hanging or passing.

#include <cdcr/zynqmp/console.hpp>

int main() {
  cdcr::zynqmp::console_write("zynqmp fault report: executing an undefined instruction\n");
  // The architecturally undefined encoding (UDF) in Thumb state, where
  // main runs.
  asm volatile("udf #0" ::: "memory");
  cdcr::zynqmp::console_write("PASS\n");  // never reached: the test fails on it
  return 0;
}
