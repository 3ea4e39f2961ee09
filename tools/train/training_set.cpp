#include "training_set.hpp"

#include <algorithm>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>

#include "cdcr/model/cable_fit.hpp"
#include "cdcr/model/chain.hpp"
#include "cdcr/model/compensation.hpp"

namespace cdcr::training {

TrainingSet TrainingSet::subset(const std::vector<int>& rows) const {
  TrainingSet s;
  s.encoding = encoding;
  const auto n = static_cast<Eigen::Index>(rows.size());
  s.cables_mm.resize(n, cables_mm.cols());
  const bool has_commanded = commanded_mm.rows() > 0;
  if (has_commanded) s.commanded_mm.resize(n, commanded_mm.cols());
  s.bends.resize(n, bends.cols());
  s.cable_residuals.resize(n, cable_residuals.cols());
  const bool has_history = history_inputs.rows() > 0;
  if (has_history) s.history_inputs.resize(n, history_inputs.cols());
  s.inputs.resize(n, inputs.cols());
  if (has_payload()) s.payload_kg.resize(n);
  s.error_twists.resize(n, 6);
  for (Eigen::Index i = 0; i < n; ++i) {
    s.cables_mm.row(i) = cables_mm.row(rows[i]);
    if (has_commanded) s.commanded_mm.row(i) = commanded_mm.row(rows[i]);
    s.bends.row(i) = bends.row(rows[i]);
    s.cable_residuals.row(i) = cable_residuals.row(rows[i]);
    if (has_history) s.history_inputs.row(i) = history_inputs.row(rows[i]);
    s.inputs.row(i) = inputs.row(rows[i]);
    if (has_payload()) s.payload_kg[i] = payload_kg[rows[i]];
    s.error_twists.row(i) = error_twists.row(rows[i]);
    s.nominal.push_back(nominal[rows[i]]);
    s.measured.push_back(measured[rows[i]]);
  }
  return s;
}

Eigen::MatrixXd encode_rows(const Eigen::MatrixXd& bends, model::InputEncoding encoding) {
  Eigen::MatrixXd inputs(bends.rows(), bends.cols());
  for (Eigen::Index i = 0; i < bends.rows(); ++i) {
    const model::JointVector<double> bend = bends.row(i).transpose();
    model::JointVector<double> x(bend.size());
    model::encode_inputs(encoding, bend, x);
    inputs.row(i) = x.transpose();
  }
  return inputs;
}

Eigen::MatrixXd model_inputs(const Eigen::MatrixXd& bends, const Eigen::MatrixXd& cable_residuals,
                             const Eigen::MatrixXd& history_inputs, const Eigen::VectorXd& payload_kg,
                             model::InputEncoding encoding) {
  const bool with_residuals = model::takes_cable_residuals(encoding);
  if (with_residuals && (cable_residuals.rows() != bends.rows() || cable_residuals.cols() < bends.cols() / 2)) {
    throw std::invalid_argument("the cable-fit encoding needs the cables' residuals of every row");
  }
  const bool with_history = model::takes_history(encoding);
  const Eigen::Index history_cols = with_history ? history_inputs.cols() : 0;
  if (with_history && (history_inputs.rows() != bends.rows() || history_cols < 3 * (bends.cols() / 2))) {
    throw std::invalid_argument("a history encoding needs where every cable of every row last moved");
  }
  if (payload_kg.size() != 0 && payload_kg.size() != bends.rows()) {
    throw std::invalid_argument("one payload per row is needed");
  }
  const Eigen::Index residual_cols = with_residuals ? cable_residuals.cols() : 0;
  Eigen::MatrixXd inputs(bends.rows(),
                         bends.cols() + residual_cols + history_cols + (payload_kg.size() > 0 ? 1 : 0));
  inputs.leftCols(bends.cols()) = encode_rows(bends, encoding);
  if (with_residuals) inputs.middleCols(bends.cols(), residual_cols) = cable_residuals;
  if (with_history) inputs.middleCols(bends.cols() + residual_cols, history_cols) = history_inputs;
  if (payload_kg.size() > 0) inputs.rightCols(1) = payload_kg;
  return inputs;
}

TrainingSet with_encoding(const TrainingSet& set, model::InputEncoding encoding) {
  TrainingSet s = set;
  s.encoding = encoding;
  s.inputs = model_inputs(s.bends, s.cable_residuals, s.history_inputs, s.payload_kg, encoding);
  return s;
}

TrainingSet with_float_cables(const TrainingSet& set, const model::RobotGeometry<double>& geometry,
                              model::InputEncoding encoding) {
  dataset::Dataset rows;
  rows.segment_count = geometry.segment_count;
  for (int i = 0; i < geometry.segment_count; ++i) rows.segment_cables.push_back(geometry.segments[i].cables.count);
  rows.cables_mm = set.cables_mm.cast<float>().cast<double>();
  rows.poses = set.measured;
  rows.has_poses = true;
  rows.payload_kg = set.payload_kg;
  rows.has_payload = set.has_payload();
  TrainingSet rounded = make_training_set(rows, geometry, model::with_history(encoding, false));
  rounded.commanded_mm = set.commanded_mm;
  if (model::takes_history(encoding)) {
    rounded.history_inputs = set.history_inputs;
    rounded = with_encoding(rounded, encoding);
  }
  return rounded;
}

TrainingSet make_training_set(const dataset::Dataset& data, const model::RobotGeometry<double>& geometry,
                              model::InputEncoding encoding, bool with_payload) {
  if (!data.has_poses) throw std::invalid_argument("dataset has no measured poses (x,y,z,qw,qx,qy,qz columns)");
  if (data.segment_count != geometry.segment_count) {
    throw std::invalid_argument("dataset has " + std::to_string(data.segment_count) + " segments, geometry has " +
                                std::to_string(geometry.segment_count));
  }
  for (int i = 0; i < geometry.segment_count; ++i) {
    if (data.cables_of(i) != geometry.segments[i].cables.count) {
      throw std::invalid_argument("dataset's segment " + std::to_string(i + 1) + " has " +
                                  std::to_string(data.cables_of(i)) + " cables, geometry's " +
                                  std::to_string(geometry.segments[i].cables.count));
    }
  }
  const int n = data.sample_count();
  const int dims = 2 * geometry.segment_count;
  TrainingSet s;
  s.cables_mm = data.cables_mm;
  s.bends.resize(n, dims);
  s.cable_residuals.resize(n, model::encoded_input_count(model::InputEncoding::bend_vector_cable_fit, geometry) - dims);
  s.error_twists.resize(n, 6);
  for (int i = 0; i < n; ++i) {
    const model::CableVector<double> cables = data.cables_mm.row(i).transpose();
    model::JointVector<double> joints;
    model::CableResiduals<double> residuals;
    bool beyond_limit = false;
    int far_segments = 0;
    if (const model::Status st =
            model::fit_measured_cables(cables, geometry, joints, residuals, 0.0, &beyond_limit, &far_segments);
        st != model::Status::ok) {
      throw std::invalid_argument("sample " + std::to_string(i + 1) + ": " + model::to_string(st));
    }
    s.far_from_consistent_rows += far_segments > 0 ? 1 : 0;
    s.beyond_limit_rows += beyond_limit ? 1 : 0;
    double residual_inputs[model::kMaxCables];
    const int residual_count = model::residual_inputs(residuals, geometry, residual_inputs);
    s.cable_residuals.row(i) = Eigen::Map<const Eigen::RowVectorXd>(residual_inputs, residual_count);
    const model::JointVector<double> bend = model::bend_from_joints(joints);
    const model::Pose<double> nominal = model::forward_kinematics_bend(bend, geometry);
    s.bends.row(i) = bend.transpose();
    s.error_twists.row(i) = model::tip_error_twist(data.poses[i], nominal).transpose();
    s.nominal.push_back(nominal);
    s.measured.push_back(data.poses[i]);
  }
  if (data.has_payload && with_payload) s.payload_kg = data.payload_kg;
  // The history is a sequence's state (make_sequence_training_set).
  if (model::takes_history(encoding)) {
    throw std::invalid_argument("the history inputs need a sequence and its hysteresis state");
  }
  s.inputs = model_inputs(s.bends, s.cable_residuals, Eigen::MatrixXd(), s.payload_kg, encoding);
  s.encoding = encoding;
  return s;
}

Split random_split(int samples, int test_count, std::uint64_t seed) {
  if (test_count < 0 || test_count >= samples) {
    throw std::invalid_argument("cannot hold out " + std::to_string(test_count) + " of " + std::to_string(samples) +
                                " samples");
  }
  std::vector<int> order(static_cast<std::size_t>(samples));
  std::iota(order.begin(), order.end(), 0);
  std::mt19937_64 rng(seed);
  std::shuffle(order.begin(), order.end(), rng);
  Split split;
  split.test.assign(order.begin(), order.begin() + test_count);
  split.train.assign(order.begin() + test_count, order.end());
  std::sort(split.test.begin(), split.test.end());
  std::sort(split.train.begin(), split.train.end());
  return split;
}

}  // namespace cdcr::training
