// The GP mean's per-point steps in Arm assembly, shared by the Cortex-M4F's
// and the Cortex-M7's mean loops (gp_mean_fpv4.hpp, gp_mean_fpv5.hpp). No
// include guard: each loop includes this, uses the macros in its asm
// statement and #undefs them after, so they reach no other code.
//
// Registers: the query in s0-s7, the block's six sums in s8-s13, the
// kernel's constants in s14, s15 (-log2(e)/2, 2 ln 2), s24 (the clamp) and
// s25-s29 (B2-B6); s16-s23 are scratch. Operands: %[z] the training
// inputs, %[a] the alphas, %[k] and %[p] two scratch core registers.

// Distance of the next training point (8 floats at z) from the query, into s16.
#define CDCR_GP_ASM_DISTANCE               \
  "vldmia %[z]!, {s16-s23}\n\t"            \
  "vsub.f32 s16, s0, s16\n\t"              \
  "vsub.f32 s17, s1, s17\n\t"              \
  "vsub.f32 s18, s2, s18\n\t"              \
  "vsub.f32 s19, s3, s19\n\t"              \
  "vsub.f32 s20, s4, s20\n\t"              \
  "vsub.f32 s21, s5, s21\n\t"              \
  "vsub.f32 s22, s6, s22\n\t"              \
  "vsub.f32 s23, s7, s23\n\t"              \
  "vmul.f32 s16, s16, s16\n\t"             \
  "vfma.f32 s16, s17, s17\n\t"             \
  "vfma.f32 s16, s18, s18\n\t"             \
  "vfma.f32 s16, s19, s19\n\t"             \
  "vfma.f32 s16, s20, s20\n\t"             \
  "vfma.f32 s16, s21, s21\n\t"             \
  "vfma.f32 s16, s22, s22\n\t"             \
  "vfma.f32 s16, s23, s23\n\t"

// polynomial_gaussian of the clamped s16 into s23, step for step: k by the
// FPU's round-to-nearest conversion, the polynomial in v, 2^k into the
// exponent bits.
#define CDCR_GP_ASM_GAUSSIAN_OF_CLAMPED    \
  "vmul.f32 s17, s16, s14\n\t"             \
  "vcvtr.s32.f32 s17, s17\n\t"             \
  "vmov %[k], s17\n\t"                     \
  "vcvt.f32.s32 s17, s17\n\t"              \
  "vfma.f32 s16, s17, s15\n\t"             \
  "vmul.f32 s18, s16, s16\n\t"             \
  "vmov.f32 s19, s25\n\t"                  \
  "vfma.f32 s19, s16, s26\n\t"             \
  "vmov.f32 s20, s27\n\t"                  \
  "vfma.f32 s20, s16, s28\n\t"             \
  "vfma.f32 s20, s18, s29\n\t"             \
  "vfma.f32 s19, s18, s20\n\t"             \
  "vmov.f32 s21, #-0.5\n\t"                \
  "vfma.f32 s21, s16, s19\n\t"             \
  "vmov.f32 s22, #1.0\n\t"                 \
  "vfma.f32 s22, s16, s21\n\t"             \
  "vmov %[p], s22\n\t"                     \
  "add %[p], %[p], %[k], lsl #23\n\t"      \
  "vmov s23, %[p]\n\t"

// The point's six terms: the first point of a block sets the sums, the
// others add to them.
#define CDCR_GP_ASM_TERMS(op)              \
  "vldmia %[a]!, {s16-s21}\n\t"            \
  op " s8, s23, s16\n\t"                   \
  op " s9, s23, s17\n\t"                   \
  op " s10, s23, s18\n\t"                  \
  op " s11, s23, s19\n\t"                  \
  op " s12, s23, s20\n\t"                  \
  op " s13, s23, s21\n\t"

// The kernel's constants into s14, s15 and s24-s29, from an 8-float array
// at %[c] in that order.
#define CDCR_GP_ASM_LOAD_CONSTANTS         \
  "vldr s14, [%[c]]\n\t"                   \
  "vldr s15, [%[c], #4]\n\t"               \
  "vldr s24, [%[c], #8]\n\t"               \
  "vldr s25, [%[c], #12]\n\t"              \
  "vldr s26, [%[c], #16]\n\t"              \
  "vldr s27, [%[c], #20]\n\t"              \
  "vldr s28, [%[c], #24]\n\t"              \
  "vldr s29, [%[c], #28]\n\t"
