#include "dataset_input.hpp"

#include <fmt/format.h>

#include "cli_errors.hpp"
#include "dataset/csv_dataset.hpp"

namespace cdcr::cli {

dataset::Dataset load_dataset(const std::string& path, bool poses_required) {
  try {
    return dataset::read_dataset_csv(path, poses_required ? dataset::PoseColumns::required
                                                          : dataset::PoseColumns::optional);
  } catch (const dataset::DatasetError& e) {
    throw InputError(e.what());
  }
}

model::RobotGeometry<double> geometry_for(const dataset::Dataset& data, const GeometryOptions& options) {
  if (options.segment_count && *options.segment_count != data.segment_count) {
    throw InputError(fmt::format("--segments is {} but the dataset has {} segments", *options.segment_count,
                                 data.segment_count));
  }
  return make_geometry(options, data.segment_count, data.segment_cables);
}

}  // namespace cdcr::cli
