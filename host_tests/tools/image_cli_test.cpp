// `cdcr inspect` and `cdcr export` on images written by the exporter (v2)
// and on a v1 image built from its specification: the JSON report read back
// field by field against the model that made the image, one damaged image per
// parser status with the check it must name, and each export format checked
// against its library encoder and objcopy.


#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <ostream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cdcr/model/compensated_kinematics.hpp"
#include "cdcr/model/flash_image.hpp"
#include "cdcr/model/gp_correction.hpp"
#include "dataset/csv_dataset.hpp"
#include "export/binary_file.hpp"
#include "export/c_source.hpp"
#include "export/image_writer.hpp"
#include "image_report.hpp"
#include "test_work_dir.hpp"

#include "../support/image_in_double.hpp"
#include "../support/random_joints.hpp"
#include "../support/run_cdcr.hpp"
#include "../support/synthetic_trained_model.hpp"
#include "../support/v1_image.hpp"

namespace cdcr::cli {
namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<std::uint8_t>;
using nlohmann::json;
using model::ImageStatus;

std::string read_text(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
}

template <typename T>
void put(Bytes& image, std::size_t offset, T value) {
  std::memcpy(image.data() + offset, &value, sizeof(T));
}

template <typename T>
T get(const Bytes& image, std::size_t offset) {
  T value;
  std::memcpy(&value, image.data() + offset, sizeof(T));
  return value;
}

// Recomputes the trailer where the header puts it, if that is inside the bytes.
void reseal(Bytes& image) {
  const auto total = get<std::uint32_t>(image, model::image_field::total_size.offset);
  if (total < 8 || total > image.size()) return;
  put<std::uint32_t>(image, total - 4, model::crc32(image.data(), total - 4));
}

using CliResult = cdcr::test_support::CliRun;

class ImageCli : public ::testing::Test {
 protected:
  void SetUp() override { dir = test_support::fresh_test_work_dir(); }

  fs::path save(const std::string& name, const Bytes& bytes) const {
    const fs::path path = dir / name;
    exporting::write_binary_file(path.string(), bytes.data(), bytes.size());
    return path;
  }

  static CliResult cdcr(const std::string& arguments) { return test_support::run_cdcr(arguments); }

  static std::string quoted(const fs::path& path) { return "'" + path.string() + "'"; }

  fs::path dir;
  training::TrainedModel model = test_support::synthetic_trained_model();
  Bytes image = exporting::write_image(model);
};

bool one_line(const std::string& text) {
  return !text.empty() && text.back() == '\n' && text.find('\n') == text.size() - 1;
}

// --- inspect: valid images ---------------------------------------------------------

TEST_F(ImageCli, InspectJsonReportsTheModel) {
  const CliResult run = cdcr("inspect --json " + quoted(save("model.img", image)));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.err, "");
  ASSERT_TRUE(one_line(run.out)) << "exactly one JSON object on one line";
  const json j = json::parse(run.out);

  EXPECT_EQ(j["valid"], true);
  EXPECT_EQ(j["status"], "ok");
  EXPECT_TRUE(j["failed_check"].is_null());
  EXPECT_EQ(j["file_size"], image.size());
  for (const char* name : {"size", "magic", "version", "header", "alignment", "checksum", "kind", "capacity", "layout",
                           "finite", "positive", "ranges", "fitted_rows", "variance"}) {
    ASSERT_TRUE(j["checks"].contains(name)) << name;
    EXPECT_EQ(j["checks"][name]["passed"], true) << name << ": " << j["checks"][name]["detail"];
  }

  const json& header = j["header"];
  EXPECT_EQ(header["magic"], "0x50474443");
  EXPECT_EQ(header["version_major"], 2);
  EXPECT_EQ(header["version_minor"], 1);
  EXPECT_EQ(header["header_size"], 64);
  EXPECT_EQ(header["variance_offset"], 0);
  EXPECT_EQ(header["variance_rank"], 0);
  EXPECT_EQ(header["total_size"], image.size());
  EXPECT_EQ(header["trailing_bytes"], 0);
  char crc[16];
  std::snprintf(crc, sizeof crc, "0x%08x", get<std::uint32_t>(image, image.size() - 4));
  EXPECT_EQ(header["crc32_stored"], crc);
  EXPECT_EQ(header["crc32_computed"], crc);

  EXPECT_EQ(j["dims"], (json{{"training_points", 5}, {"input_dims", 4}, {"output_dims", 6}, {"segments", 2}}));
  EXPECT_EQ(j["version"], "2.1");
  EXPECT_EQ(j["model_kind"], (json{{"code", 1}, {"name", "exact-gp"}}));
  EXPECT_EQ(j["extra_inputs"], 0);
  EXPECT_EQ(j["fitted_rows"], 5);
  EXPECT_EQ(j["scalar_type"]["name"], "float32");
  EXPECT_EQ(j["kernel"]["code"], 1);
  EXPECT_EQ(j["input_encoding"]["name"], "bend-vector");

  // Numbers are printed as the shortest decimal of the float32: reading them
  // back as float must give the stored value exactly.
  const auto as_float = [](const json& value) { return static_cast<float>(value.get<double>()); };
  ASSERT_EQ(j["geometry"].size(), 2u);
  for (int s = 0; s < 2; ++s) {
    EXPECT_EQ(as_float(j["geometry"][s]["backbone_length_mm"]),
              static_cast<float>(model.geometry.segments[s].backbone_length_mm));
    EXPECT_EQ(as_float(j["geometry"][s]["theta_max_rad"]), static_cast<float>(model.geometry.segments[s].theta_max_rad));
  }
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(as_float(j["normalisation"]["input_mean"][k]), static_cast<float>(model.input_mean[k]));
    EXPECT_EQ(as_float(j["normalisation"]["input_scale"][k]), static_cast<float>(model.input_scale[k]));
    EXPECT_EQ(as_float(j["hyperparameters"]["length_scales"][k]), static_cast<float>(model.length_scales[k]));
  }
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(as_float(j["input_range"]["input_min"][k]), static_cast<float>(model.inputs.col(k).minCoeff()));
    EXPECT_EQ(as_float(j["input_range"]["input_max"][k]), static_cast<float>(model.inputs.col(k).maxCoeff()));
  }
  for (int k = 0; k < 6; ++k) {
    EXPECT_EQ(as_float(j["normalisation"]["output_mean"][k]), static_cast<float>(model.output_mean[k]));
    EXPECT_EQ(as_float(j["hyperparameters"]["noise_variance"][k]), static_cast<float>(model.noise_variance[k]));
  }

  const model::ImageLayout layout = model::image_layout(5, 4, 2);
  const json expected_blocks = json::array({
      {{"name", "header"}, {"offset", 0}, {"size", 64}, {"inside_file", true}},
      {{"name", "geometry"}, {"offset", 64}, {"size", 24}, {"inside_file", true}},
      {{"name", "parameters"}, {"offset", layout.parameters_offset}, {"size", 176}, {"inside_file", true}},
      {{"name", "inputs"}, {"offset", layout.inputs_offset}, {"size", 80}, {"inside_file", true}},
      {{"name", "alpha"}, {"offset", layout.alpha_offset}, {"size", 120}, {"inside_file", true}},
      {{"name", "metadata"}, {"offset", layout.metadata_offset}, {"size", 88}, {"inside_file", true}},
      {{"name", "crc32"}, {"offset", layout.total_size - 4}, {"size", 4}, {"inside_file", true}},
  });
  EXPECT_EQ(j["blocks"], expected_blocks);

  const json& meta = j["metadata"];
  char hash[32];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(model.dataset_hash));
  EXPECT_EQ(meta["dataset_hash"], hash);
  EXPECT_EQ(meta["created_unix_s"], 1700000000);
  EXPECT_EQ(meta["created_utc"], "2023-11-14T22:13:20Z");
  EXPECT_EQ(meta["validation_samples"], 70);
  EXPECT_EQ(meta["trainer"], "cdcr-test 0.1.0");
  EXPECT_EQ(meta["metrics"]["initial_position_mm"], 3.25);
  EXPECT_EQ(meta["metrics"]["compensated_orientation_deg"], 0.25);
  EXPECT_EQ(as_float(meta["metrics"]["float32_max_position_diff_mm"]), 0.004f);
  EXPECT_EQ(as_float(meta["metrics"]["float32_mean_orientation_diff_deg"]), 0.0001f);
}

TEST_F(ImageCli, InspectTextShowsEveryCheck) {
  const CliResult run = cdcr("inspect " + quoted(save("model.img", image)));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.err, "");
  for (const char* expected :
       {"  magic               0x50474443 (CDGP)\n", "  version             2.1\n", "  training points     5\n",
        "  fitted rows         5\n", "  model kind          1 (exact-gp)\n", "  variance factor     none\n",
        "  segments            2\n", "  input encoding      2 (bend-vector)\n",
        "  created             2023-11-14T22:13:20Z (unix 1700000000)\n", "  trainer             \"cdcr-test 0.1.0\"\n",
        "  checksum    pass", "  capacity    pass", "  positive    pass", "  ranges      pass", "  fitted_rows pass",
        "\nvalid\n"}) {
    EXPECT_NE(run.out.find(expected), std::string::npos) << expected << "\n--- output ---\n" << run.out;
  }
  EXPECT_EQ(run.out.find("FAIL"), std::string::npos);
}

TEST_F(ImageCli, TrailingBytesAreReportedNotRefused) {
  Bytes region = image;
  region.resize(image.size() + 100, 0xFF);
  const CliResult run = cdcr("inspect --json " + quoted(save("region.img", region)));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const json j = json::parse(run.out);
  EXPECT_EQ(j["valid"], true);
  EXPECT_EQ(j["header"]["trailing_bytes"], 100);
  EXPECT_EQ(j["file_size"], image.size() + 100);
}

// --- inspect: damaged images -------------------------------------------------------

TEST_F(ImageCli, InspectOfAFlippedByteStillShowsTheImage) {
  Bytes flipped = image;
  flipped[model::image_layout(5, 4, 2).alpha_offset + 3] ^= 0x40;
  const CliResult run = cdcr("inspect --json " + quoted(save("flipped.img", flipped)));
  EXPECT_EQ(run.exit_code, 1);
  ASSERT_TRUE(one_line(run.err)) << run.err;
  EXPECT_NE(run.err.find("checksum_mismatch"), std::string::npos) << run.err;
  ASSERT_TRUE(one_line(run.out));
  const json j = json::parse(run.out);
  EXPECT_EQ(j["valid"], false);
  EXPECT_EQ(j["status"], "checksum_mismatch");
  EXPECT_EQ(j["failed_check"], "checksum");
  EXPECT_EQ(j["checks"]["checksum"]["passed"], false);
  EXPECT_EQ(j["checks"]["magic"]["passed"], true);
  EXPECT_EQ(j["checks"]["finite"]["passed"], true);
  EXPECT_NE(j["header"]["crc32_stored"], j["header"]["crc32_computed"]);
  EXPECT_EQ(j["dims"]["training_points"], 5);
  EXPECT_EQ(j["metadata"]["trainer"], "cdcr-test 0.1.0");
}

TEST_F(ImageCli, InspectOfATruncatedImage) {
  const Bytes truncated(image.begin(), image.end() - 10);
  const CliResult text = cdcr("inspect " + quoted(save("truncated.img", truncated)));
  EXPECT_EQ(text.exit_code, 1);
  ASSERT_TRUE(one_line(text.err)) << text.err;
  EXPECT_NE(text.err.find("(truncated)"), std::string::npos) << text.err;
  EXPECT_NE(text.out.find("  size        FAIL"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("  checksum    not checked"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("invalid: size check failed (truncated: "), std::string::npos) << text.out;

  // Without only its trailer, everything but the checksum can still be shown.
  const CliResult run = cdcr("inspect --json " + quoted(save("no_trailer.img", Bytes(image.begin(), image.end() - 4))));
  EXPECT_EQ(run.exit_code, 1);
  const json j = json::parse(run.out);
  EXPECT_EQ(j["status"], "truncated");
  EXPECT_EQ(j["failed_check"], "size");
  EXPECT_TRUE(j["checks"]["checksum"]["passed"].is_null());
  EXPECT_EQ(j["metadata"]["trainer"], "cdcr-test 0.1.0");
  EXPECT_EQ(j["checks"]["finite"]["passed"], true);
  EXPECT_EQ(j["blocks"].back()["name"], "crc32");
  EXPECT_EQ(j["blocks"].back()["inside_file"], false);
}

TEST_F(ImageCli, InspectOfAFileShorterThanAHeader) {
  const CliResult run = cdcr("inspect --json " + quoted(save("short.img", Bytes(image.begin(), image.begin() + 20))));
  EXPECT_EQ(run.exit_code, 1);
  ASSERT_TRUE(one_line(run.err));
  const json j = json::parse(run.out);
  EXPECT_EQ(j["status"], "truncated");
  EXPECT_EQ(j["header"]["magic"], "0x50474443");
  EXPECT_EQ(j["header"]["version_major"], 2);
  EXPECT_TRUE(j["dims"].is_null());
  EXPECT_TRUE(j["fitted_rows"].is_null());
  EXPECT_EQ(j["checks"]["magic"]["passed"], true);
  EXPECT_TRUE(j["checks"]["header"]["passed"].is_null());
}

TEST_F(ImageCli, InspectOfAMissingFile) {
  const CliResult run = cdcr("inspect " + quoted(dir / "missing.img"));
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_TRUE(one_line(run.err)) << run.err;
  EXPECT_EQ(run.out, "");
}

// Each damaged image: the report's status is the parser's, and the check it
// names has failed.
struct Damage {
  const char* name;
  ImageStatus status;
  const char* check;
};

void PrintTo(const Damage& d, std::ostream* os) { *os << d.name; }

class ImageReportDamage : public ImageCli, public ::testing::WithParamInterface<Damage> {
 protected:
  Bytes damaged(const std::string& name) const {
    namespace field = model::image_field;
    const model::ImageLayout layout = model::image_layout(5, 4, 2);
    Bytes bad = image;
    if (name == "short") return Bytes(image.begin(), image.begin() + 40);
    if (name == "truncated") return Bytes(image.begin(), image.end() - 1);
    if (name == "magic") bad[0] = 'X';
    if (name == "version") put<std::uint16_t>(bad, field::version_major.offset, 3);
    if (name == "header_size") put<std::uint32_t>(bad, field::header_size.offset, 32);
    if (name == "reserved") bad[field::hysteresis_operators.offset] = 7;
    if (name == "variance") {  // a variance block in a v2.0 image
      put<std::uint16_t>(bad, field::version_minor.offset, 0);
      put<std::uint32_t>(bad, field::variance_offset.offset, layout.metadata_offset);
    }
    if (name == "model_kind") bad[field::model_kind.offset] = 3;
    if (name == "extra_inputs") bad[field::extra_inputs.offset] = 2;  // one is the payload input
    if (name == "dims") put<std::uint16_t>(bad, field::input_dims.offset, 3);
    if (name == "offset_alignment") put<std::uint32_t>(bad, field::alpha_offset.offset, layout.alpha_offset + 4);
    if (name == "checksum") bad[layout.inputs_offset] ^= 1;
    if (name == "kind") bad[field::kernel_kind.offset] = 9;
    if (name == "layout") put<std::uint32_t>(bad, field::metadata_offset.offset, layout.metadata_offset + 8);
    if (name == "nan") put<float>(bad, layout.inputs_offset + 8, std::numeric_limits<float>::quiet_NaN());
    if (name == "zero_scale") put<float>(bad, layout.parameters_offset + 4 * 5, 0.0f);
    if (name == "negative_radius") put<float>(bad, 64 + 4, -67.0f);
    const std::uint32_t input_min = layout.parameters_offset + 4 * (3 * 4 + 4 * 6);
    if (name == "range_nan") put<float>(bad, input_min + 4 * 5, std::numeric_limits<float>::quiet_NaN());
    if (name == "inverted_range") put<float>(bad, input_min + 4, get<float>(bad, input_min + 4 * 5) + 1.0f);
    if (name == "fitted_rows") {
      put<std::uint32_t>(bad, layout.metadata_offset + model::image_metadata_field::fitted_rows, 0);
    }
    if (name == "v1_reserved") {
      bad = test_support::v1_image(model);
      bad[field::model_kind.offset] = 2;  // a v2 field in a v1 image: reserved there
    }
    if (name != "checksum") reseal(bad);
    return bad;
  }
};

TEST_P(ImageReportDamage, NamesTheParsersStatusAndCheck) {
  const Damage d = GetParam();
  Bytes bytes;
  if (std::string(d.name) == "capacity") {
    test_support::SyntheticModelOptions options;
    options.training_points = static_cast<int>(model::kMaxTrainingPoints) + 1;
    options.segments = 1;
    bytes = exporting::write_image(test_support::synthetic_trained_model(options));
  } else {
    bytes = damaged(d.name);
  }
  model::ImageView view{};
  ASSERT_EQ(model::parse_image(bytes.data(), bytes.size(), view), d.status);

  const ImageReport report = inspect_image(bytes.data(), bytes.size());
  EXPECT_EQ(report.status, d.status);
  ASSERT_NE(report.failed_check(), nullptr);
  EXPECT_STREQ(report.failed_check()->name, d.check);
  EXPECT_EQ(report.failed_check()->result, CheckResult::failed) << report.failed_check()->detail;

  const CliResult run = cdcr("inspect --json " + quoted(save("damaged.img", bytes)));
  EXPECT_EQ(run.exit_code, 1);
  ASSERT_TRUE(one_line(run.err)) << run.err;
  EXPECT_NE(run.err.find(std::string("(") + image_status_name(d.status) + ")"), std::string::npos) << run.err;
  const json j = json::parse(run.out);
  EXPECT_EQ(j["status"], image_status_name(d.status));
  EXPECT_EQ(j["failed_check"], d.check);
  EXPECT_EQ(j["checks"][d.check]["passed"], false);
}

INSTANTIATE_TEST_SUITE_P(
    EveryStatus, ImageReportDamage,
    ::testing::Values(Damage{"short", ImageStatus::truncated, "size"},
                      Damage{"truncated", ImageStatus::truncated, "size"},
                      Damage{"magic", ImageStatus::bad_magic, "magic"},
                      Damage{"version", ImageStatus::unsupported_version, "version"},
                      Damage{"header_size", ImageStatus::bad_header, "header"},
                      Damage{"reserved", ImageStatus::bad_header, "header"},
                      Damage{"dims", ImageStatus::bad_header, "header"},
                      Damage{"offset_alignment", ImageStatus::misaligned, "alignment"},
                      Damage{"checksum", ImageStatus::checksum_mismatch, "checksum"},
                      Damage{"kind", ImageStatus::unsupported_kind, "kind"},
                      Damage{"capacity", ImageStatus::over_capacity, "capacity"},
                      Damage{"layout", ImageStatus::size_mismatch, "layout"},
                      Damage{"nan", ImageStatus::non_finite_payload, "finite"},
                      Damage{"zero_scale", ImageStatus::invalid_parameters, "positive"},
                      Damage{"negative_radius", ImageStatus::invalid_parameters, "positive"},
                      Damage{"variance", ImageStatus::bad_header, "header"},
                      Damage{"model_kind", ImageStatus::unsupported_kind, "kind"},
                      Damage{"extra_inputs", ImageStatus::unsupported_kind, "kind"},
                      Damage{"range_nan", ImageStatus::non_finite_payload, "finite"},
                      Damage{"inverted_range", ImageStatus::invalid_parameters, "ranges"},
                      Damage{"fitted_rows", ImageStatus::invalid_parameters, "fitted_rows"},
                      Damage{"v1_reserved", ImageStatus::bad_header, "header"}),
    [](const ::testing::TestParamInfo<Damage>& info) { return std::string(info.param.name); });

// The report's checks are the parser's: on any prefix or single damaged byte
// its verdict is the plain parse's, and the check it names as failed has
// failed with words to say why.
TEST_F(ImageCli, ReportAgreesWithTheParserOnEveryDamage) {
  const auto expect_agreement = [](const Bytes& bytes, const std::string& what) {
    model::ImageView view{};
    const ImageStatus status = model::parse_image(bytes.data(), bytes.size(), view);
    const ImageReport report = inspect_image(bytes.data(), bytes.size());
    ASSERT_EQ(report.status, status) << what;
    if (status == ImageStatus::ok) {
      for (const ImageCheck& check : report.checks) EXPECT_EQ(check.result, CheckResult::passed) << what << " " << check.name;
      return;
    }
    ASSERT_NE(report.failed_check(), nullptr) << what;
    EXPECT_EQ(report.failed_check()->result, CheckResult::failed) << what;
    EXPECT_FALSE(report.failed_check()->detail.empty()) << what << ": " << report.failed_check()->name;
  };
  for (std::size_t length = 0; length <= image.size(); ++length) {
    expect_agreement(Bytes(image.begin(), image.begin() + static_cast<std::ptrdiff_t>(length)),
                     "prefix " + std::to_string(length));
  }
  for (std::size_t i = 0; i < image.size(); ++i) {
    for (std::uint8_t mask : {std::uint8_t{0x01}, std::uint8_t{0x80}, std::uint8_t{0xFF}}) {
      Bytes bad = image;
      bad[i] ^= mask;
      expect_agreement(bad, "byte " + std::to_string(i) + " ^ " + std::to_string(mask));
      reseal(bad);  // past the CRC to the checks behind it
      expect_agreement(bad, "resealed byte " + std::to_string(i) + " ^ " + std::to_string(mask));
    }
  }
}

// Two independent faults behind a valid CRC: the verdict names the first,
// the checks show both, each in its own words.
TEST_F(ImageCli, InspectShowsEveryIndependentFault) {
  const model::ImageLayout layout = model::image_layout(5, 4, 2);
  Bytes bad = image;
  bad[model::image_field::model_kind.offset] = 7;
  put<float>(bad, layout.inputs_offset + 4 * 3, std::numeric_limits<float>::infinity());
  reseal(bad);
  const CliResult run = cdcr("inspect --json " + quoted(save("two_faults.img", bad)));
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("(unsupported_kind)"), std::string::npos) << run.err;
  const json j = json::parse(run.out);
  EXPECT_EQ(j["status"], "unsupported_kind");
  EXPECT_EQ(j["failed_check"], "kind");
  EXPECT_EQ(j["checks"]["kind"]["passed"], false);
  EXPECT_EQ(j["checks"]["kind"]["detail"], "model_kind 7 unknown");
  EXPECT_EQ(j["checks"]["finite"]["passed"], false);
  EXPECT_EQ(j["checks"]["finite"]["detail"], "inputs[3] is inf");
  EXPECT_EQ(j["checks"]["positive"]["passed"], true);
  EXPECT_EQ(j["checks"]["checksum"]["passed"], true);
  EXPECT_TRUE(j["model_kind"]["name"].is_null());

  const CliResult text = cdcr("inspect " + quoted(save("two_faults.img", bad)));
  EXPECT_NE(text.out.find("  kind        FAIL         model_kind 7 unknown\n"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("  finite      FAIL         inputs[3] is inf\n"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("\ninvalid: kind check failed (unsupported_kind: "), std::string::npos) << text.out;
}

TEST_F(ImageCli, InspectOfASparseModel) {
  training::TrainedModel sparse = model;
  sparse.kind = model::ImageModelKind::sparse_gp;
  sparse.fitted_rows = 640;
  const CliResult run = cdcr("inspect --json " + quoted(save("sparse.img", exporting::write_image(sparse))));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const json j = json::parse(run.out);
  EXPECT_EQ(j["model_kind"], (json{{"code", 2}, {"name", "sparse-gp"}}));
  EXPECT_EQ(j["dims"]["training_points"], 5);
  EXPECT_EQ(j["fitted_rows"], 640);
  EXPECT_EQ(j["checks"]["fitted_rows"]["passed"], true);

  const CliResult text = cdcr("inspect " + quoted(save("sparse.img", exporting::write_image(sparse))));
  EXPECT_NE(text.out.find("  inducing points     5\n  fitted rows         640\n"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("  model kind          2 (sparse-gp)\n"), std::string::npos) << text.out;
}

// A v2.2 image's hysteresis block: its counts in the header, its values
// in the text and the JSON, and the check that passed on them.
TEST_F(ImageCli, InspectShowsTheHysteresisBlock) {
  test_support::SyntheticModelOptions options;
  options.hysteresis_operators = 2;
  const training::TrainedModel m = test_support::synthetic_trained_model(options);
  const fs::path path = save("hysteresis.img", exporting::write_image(m));
  const CliResult run = cdcr("inspect --json " + quoted(path));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const json j = json::parse(run.out);
  EXPECT_EQ(j["version"], "2.2");
  EXPECT_EQ(j["header"]["hysteresis_cables"], 8);
  EXPECT_EQ(j["header"]["hysteresis_operators"], 2);
  ASSERT_TRUE(j["hysteresis"].is_object()) << run.out;
  EXPECT_EQ(j["hysteresis"]["cables"], 8);
  EXPECT_EQ(j["hysteresis"]["operators"], 2);
  ASSERT_EQ(j["hysteresis"]["widths_mm"].size(), 16u);
  EXPECT_EQ(j["hysteresis"]["widths_mm"][3].get<float>(), static_cast<float>(m.hysteresis.widths_mm[1][1]));
  EXPECT_EQ(j["hysteresis"]["weights"][4].get<float>(), static_cast<float>(m.hysteresis.weights[2][0]));
  EXPECT_EQ(j["hysteresis"]["homing_lags_mm"][15].get<float>(), static_cast<float>(m.hysteresis.homing_lag_mm[7][1]));
  EXPECT_EQ(j["checks"]["hysteresis"]["passed"], true);
  bool listed = false;
  for (const json& block : j["blocks"]) listed = listed || block["name"] == "hysteresis";
  EXPECT_TRUE(listed);

  const CliResult text = cdcr("inspect " + quoted(path));
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("  hysteresis          8 cables, 2 operators each\n"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("cable hysteresis (2 play operators per cable"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("  hysteresis  pass"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("8 cables x 2 play operators: widths within [0, 2] mm"), std::string::npos) << text.out;

  // A joints-only image says it has none.
  const json plain = json::parse(cdcr("inspect --json " + quoted(save("model.img", image))).out);
  EXPECT_TRUE(plain["hysteresis"].is_null());
  EXPECT_EQ(plain["checks"]["hysteresis"]["detail"], "no hysteresis block");
}

// A bad value in the block, under a valid CRC: the check names it.
TEST_F(ImageCli, InspectNamesABadHysteresisValue) {
  test_support::SyntheticModelOptions options;
  options.hysteresis_operators = 1;
  Bytes bad = exporting::write_image(test_support::synthetic_trained_model(options));
  const model::ImageLayout layout = model::image_layout(5, 4, 2, 2, 0, 0, model::image_hysteresis_floats(8, 1));
  put<float>(bad, layout.hysteresis_offset + 4 * 2, 3.5f);  // cable 3's width
  put<std::uint32_t>(bad, bad.size() - 4, model::crc32(bad.data(), bad.size() - 4));
  const CliResult run = cdcr("inspect --json " + quoted(save("bad_hysteresis.img", bad)));
  EXPECT_EQ(run.exit_code, 1);
  const json j = json::parse(run.out);
  EXPECT_EQ(j["status"], "invalid_parameters");
  EXPECT_EQ(j["failed_check"], "hysteresis");
  EXPECT_NE(j["checks"]["hysteresis"]["detail"].get<std::string>().find("hysteresis_width[2] 3.5, expected at most 2"),
            std::string::npos)
      << j["checks"]["hysteresis"]["detail"];
}

// An image with a hysteresis block evaluated on rows without time (not a
// motion sequence): one line saying so, exit 1.
TEST_F(ImageCli, EvalOfAHysteresisImageNeedsAMotionSequence) {
  const fs::path data = dir / "data.csv";
  ASSERT_EQ(cdcr("simulate --samples 12 --seed 4 --out " + quoted(data)).exit_code, 0);
  test_support::SyntheticModelOptions options;
  options.segments = dataset::read_dataset_csv(data.string()).segment_count;
  options.hysteresis_operators = 1;
  const fs::path path = save("hysteresis.img", exporting::write_image(test_support::synthetic_trained_model(options)));
  const CliResult run = cdcr("eval --model " + quoted(path) + " --data " + quoted(data));
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_TRUE(one_line(run.err)) << run.err;
  EXPECT_NE(run.err.find("needs a motion sequence (a t_s column), but the rows have no time"), std::string::npos)
      << run.err;
  options.hysteresis_operators = 0;
  const fs::path plain = save("plain.img", exporting::write_image(test_support::synthetic_trained_model(options)));
  EXPECT_EQ(cdcr("eval --model " + quoted(plain) + " --data " + quoted(data)).exit_code, 0);
}

// cdcr eval on a motion sequence with a hysteresis image: the poses are
// those of the effective lengths, the state carried from row to row and each
// session from home. Measured poses made in double from the trained model's
// own hysteresis and the image's GP are met to float32 rounding; the same
// model without its block (joints-only) misses them by the lags.
TEST_F(ImageCli, EvalOfASequenceCarriesTheHysteresisFromRowToRow) {
  test_support::SyntheticModelOptions options;
  options.hysteresis_operators = 2;
  options.position_output_factor = 0.1;
  options.rotation_output_factor = 0.001;
  const training::TrainedModel m = test_support::synthetic_trained_model(options);
  const Bytes with_block = exporting::write_image(m);
  training::TrainedModel joints_only = m;
  joints_only.hysteresis = model::HysteresisModel<double>{};
  test_support::ImageInDouble reference;
  ASSERT_TRUE(test_support::read_image_in_double(with_block, reference));
  const model::RobotGeometry<double>& geometry = reference.geometry;

  dataset::Dataset data;
  data.segment_count = 2;
  data.has_time = true;
  data.has_poses = true;
  const int rows = 80;
  data.cables_mm.resize(rows, 8);
  data.time_s.resize(rows);
  data.session_starts = {0, 50};
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> step(-0.04, 0.04);
  model::JointVector<double> joints(4);
  joints << 0.3, 0.12, 2.0, 0.1;
  model::HysteresisState<double> state;
  for (int i = 0; i < rows; ++i) {
    model::CableVector<double> cables;
    ASSERT_EQ(test_support::random_walk_step(joints, rng, step, geometry, cables), model::Status::ok);
    // What the CSV carries: the reader's value of the written text.
    data.cables_mm.row(i) = cables.transpose();
    data.time_s[i] = 0.05 * i + (i >= 50 ? 100.0 : 0.0);
    if (i == 0 || i == 50) ASSERT_EQ(model::start_at_home(state, m.hysteresis, geometry), model::Status::ok);
    model::update_hysteresis(state, m.hysteresis, cables);
    model::CableVector<double> effective;
    model::effective_lengths(state, m.hysteresis, effective);
    model::ForwardResult<double> truth;
    ASSERT_EQ(model::compensated_forward(effective, geometry, reference.correction, truth), model::Status::ok);
    data.poses.push_back(truth.compensated);
  }
  const fs::path data_path = dir / "sequence.csv";
  dataset::write_dataset_csv(data_path.string(), data);

  const CliResult run = cdcr("eval --json --model " + quoted(save("hysteresis.img", with_block)) + " --data " +
                             quoted(data_path));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const json j = json::parse(run.out);
  EXPECT_EQ(j["hysteresis"], "carried over the sequence");
  EXPECT_LT(j["compensated"]["position_mm"].get<double>(), 0.002) << run.out;
  EXPECT_LT(j["compensated"]["orientation_deg"].get<double>(), 0.001) << run.out;

  const CliResult without = cdcr("eval --json --model " +
                                 quoted(save("joints_only.img", exporting::write_image(joints_only))) + " --data " +
                                 quoted(data_path));
  ASSERT_EQ(without.exit_code, 0) << without.err;
  const json k = json::parse(without.out);
  EXPECT_EQ(k["hysteresis"], "none");
  EXPECT_GT(k["compensated"]["position_mm"].get<double>(), 0.05) << without.out;

  const CliResult text = cdcr("eval --model " + quoted(save("hysteresis.img", with_block)) + " --data " +
                              quoted(data_path));
  EXPECT_NE(text.out.find("hysteresis           carried from row to row over 2 session(s), each from home"),
            std::string::npos)
      << text.out;
}

// A v1 image, built from its specification, goes through every tool that
// reads images, as before.
TEST_F(ImageCli, V1ImageLoadsEverywhere) {
  const fs::path data = dir / "data.csv";
  ASSERT_EQ(cdcr("simulate --samples 12 --seed 4 --out " + quoted(data)).exit_code, 0);
  test_support::SyntheticModelOptions options;
  options.segments = dataset::read_dataset_csv(data.string()).segment_count;
  const training::TrainedModel m = test_support::synthetic_trained_model(options);
  const Bytes v1 = test_support::v1_image(m);
  const fs::path v1_path = save("model_v1.img", v1);
  const fs::path v2_path = save("model_v2.img", exporting::write_image(m));

  const CliResult inspect = cdcr("inspect --json " + quoted(v1_path));
  ASSERT_EQ(inspect.exit_code, 0) << inspect.err;
  const json j = json::parse(inspect.out);
  EXPECT_EQ(j["valid"], true);
  EXPECT_EQ(j["header"]["version_major"], 1);
  EXPECT_EQ(j["version"], "1.0");
  EXPECT_EQ(j["model_kind"]["name"], "exact-gp");
  EXPECT_EQ(j["fitted_rows"], 5);
  EXPECT_TRUE(j["input_range"].is_null());
  EXPECT_FALSE(j["header"].contains("variance_offset"));
  EXPECT_TRUE(j["checks"]["ranges"]["passed"].is_null());
  EXPECT_TRUE(j["checks"]["fitted_rows"]["passed"].is_null());
  for (const char* name : {"size", "magic", "version", "header", "alignment", "checksum", "kind", "capacity", "layout",
                           "finite", "positive"}) {
    EXPECT_EQ(j["checks"][name]["passed"], true) << name << ": " << j["checks"][name]["detail"];
  }
  EXPECT_EQ(j["blocks"][2]["size"], 4 * (3 * 2 * options.segments + 24));

  const fs::path exported = dir / "v1.bin";
  const CliResult export_run = cdcr("export --model " + quoted(v1_path) + " --format bin --out " + quoted(exported));
  ASSERT_EQ(export_run.exit_code, 0) << export_run.err;
  EXPECT_EQ(exporting::read_binary_file(exported.string()), v1);

  // The same float32 model in either format: the same errors. Only v2 holds
  // the input ranges that tell extrapolating rows.
  const CliResult eval_v1 = cdcr("eval --json --model " + quoted(v1_path) + " --data " + quoted(data));
  const CliResult eval_v2 = cdcr("eval --json --model " + quoted(v2_path) + " --data " + quoted(data));
  ASSERT_EQ(eval_v1.exit_code, 0) << eval_v1.err;
  ASSERT_EQ(eval_v2.exit_code, 0) << eval_v2.err;
  const json v1_errors = json::parse(eval_v1.out);
  const json v2_errors = json::parse(eval_v2.out);
  for (const char* key : {"n", "initial", "compensated"}) EXPECT_EQ(v1_errors[key], v2_errors[key]) << key;
  EXPECT_EQ(v1_errors["outside_range"], 0);
  EXPECT_EQ(v1_errors["n"], 12);
}

TEST(ImageStatusNames, AreDistinctIdentifiers) {
  std::vector<std::string> names;
  for (int s = 0; s <= static_cast<int>(ImageStatus::invalid_parameters); ++s) {
    const std::string name = image_status_name(static_cast<ImageStatus>(s));
    EXPECT_EQ(name.find_first_not_of("abcdefghijklmnopqrstuvwxyz_"), std::string::npos) << name;
    for (const std::string& other : names) EXPECT_NE(name, other);
    names.push_back(name);
  }
}

// --- export ------------------------------------------------------------------------

TEST_F(ImageCli, ExportBinaryWritesOnlyTheImage) {
  Bytes region = image;
  region.resize(image.size() + 64, 0xFF);
  const fs::path out = dir / "model.bin";
  const CliResult run = cdcr("export --model " + quoted(save("region.img", region)) + " --format bin --out " + quoted(out));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.err, "");
  EXPECT_TRUE(one_line(run.out)) << run.out;
  EXPECT_EQ(exporting::read_binary_file(out.string()), image);
}

TEST_F(ImageCli, ExportHexDecodesToTheImage) {
#ifndef CDCR_OBJCOPY
  FAIL() << "objcopy not found: install binutils (build-essential), which CMake finds as CDCR_OBJCOPY";
#else
  const fs::path out = dir / "model.hex";
  const CliResult run = cdcr("export --model " + quoted(save("model.img", image)) +
                       " --format hex --base-address 0x08040000 --record-bytes 32 --out " + quoted(out));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("0x08040000"), std::string::npos) << run.out;
  const std::string text = read_text(out);
  EXPECT_EQ(text.rfind(":020000040804EE\n", 0), 0u) << text.substr(0, 40);
  const std::string decode = "'" CDCR_OBJCOPY "' -I ihex -O binary " + quoted(out) + " " + quoted(dir / "decoded.bin");
  ASSERT_EQ(std::system(decode.c_str()), 0);
  EXPECT_EQ(exporting::read_binary_file((dir / "decoded.bin").string()), image);
#endif
}

TEST_F(ImageCli, ExportCSourceUsesTheChosenNames) {
  const fs::path out = dir / "model.c";
  const CliResult run = cdcr("export --model " + quoted(save("model.img", image)) +
                       " --format c --symbol arm_model --section .arm_model_flash --out " + quoted(out));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  exporting::CSourceOptions options;
  options.symbol = "arm_model";
  options.section = ".arm_model_flash";
  options.description = "Exported from " + (dir / "model.img").string() + " by cdcr export.";
  EXPECT_EQ(read_text(out), exporting::format_c_source(image.data(), image.size(), options));
}

TEST_F(ImageCli, ExportRefusesAnInvalidImageAndWritesNothing) {
  Bytes flipped = image;
  flipped[100] ^= 0xFF;
  const fs::path model_path = save("flipped.img", flipped);
  for (const char* format : {"bin", "hex", "c"}) {
    const fs::path out = dir / (std::string("out.") + format);
    const CliResult run = cdcr("export --model " + quoted(model_path) + " --format " + format + " --out " + quoted(out));
    EXPECT_EQ(run.exit_code, 1) << format;
    EXPECT_TRUE(one_line(run.err)) << run.err;
    EXPECT_NE(run.err.find("checksum_mismatch"), std::string::npos) << run.err;
    EXPECT_EQ(run.out, "");
    EXPECT_FALSE(fs::exists(out)) << format;
  }
}

TEST_F(ImageCli, ExportUsageErrors) {
  const std::string model_path = quoted(save("model.img", image));
  const std::string out = " --out " + quoted(dir / "out");
  for (const std::string& arguments :
       {"--format elf" + out, "--format bin --base-address 0x1000" + out, "--format hex --symbol name" + out,
        "--format hex --base-address 0x0804zz" + out, "--format c --symbol 9lives" + out,
        "--format hex --record-bytes 20" + out, "--format c --section 'a b'" + out, std::string("--format bin")}) {
    const CliResult run = cdcr("export --model " + model_path + " " + arguments);
    EXPECT_EQ(run.exit_code, 2) << arguments << ": " << run.err;
    EXPECT_TRUE(one_line(run.err)) << run.err;
  }
  const CliResult beyond = cdcr("export --model " + model_path + " --format hex --base-address 0xFFFFFF00" + out);
  EXPECT_EQ(beyond.exit_code, 1) << beyond.err;
  EXPECT_TRUE(one_line(beyond.err)) << beyond.err;
}

}  // namespace
}  // namespace cdcr::cli
