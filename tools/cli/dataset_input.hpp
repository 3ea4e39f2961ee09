#pragma once
// Loading a dataset for a command: read the CSV, build the geometry from the
// geometry flags and the dataset's segment count, and turn any rejection into
// an InputError with the file and line.

#include <string>

#include "dataset/dataset.hpp"
#include "geometry_options.hpp"

namespace cdcr::cli {

dataset::Dataset load_dataset(const std::string& path, bool poses_required);

model::RobotGeometry<double> geometry_for(const dataset::Dataset& data, const GeometryOptions& options);

}  // namespace cdcr::cli
