#pragma once
// Umbrella header for the model library.

#include "cdcr/model/chain.hpp"
#include "cdcr/model/compensation.hpp"
#include "cdcr/model/geometry.hpp"
#include "cdcr/model/inverse_kinematics.hpp"
#include "cdcr/model/se3.hpp"
#include "cdcr/model/segment.hpp"
#include "cdcr/model/status.hpp"
#include "cdcr/model/types.hpp"
