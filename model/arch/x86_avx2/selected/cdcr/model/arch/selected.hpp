#pragma once
// The architecture the build selected (CDCR_MODEL_ARCH=x86_avx2, the default
// on an x86-64 host whose CPU has AVX2 and FMA): the GP loops eight training
// points at a time, in the boards' arithmetic.

#include "cdcr/model/arch/x86_avx2.hpp"

namespace cdcr::model::arch {
using Selected = X86Avx2;
}  // namespace cdcr::model::arch
