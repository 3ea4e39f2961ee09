// Writes the flash images the CLI tests read, into the directory given as the
// only argument: valid ones from synthetic models, and damaged copies.
//
//   model.img           5 training points, 2 segments
//   model_v1.img        the same model in format v1, built from its specification
//   model_trailing.img  model.img followed by 100 bytes of erased flash (0xFF)
//   truncated.img       model.img without its last 10 bytes
//   flipped.img         model.img with one byte of the alpha block inverted
//   header_only.img     the first 20 bytes of model.img
//   large.img           800 points, 8 segments: more than 64 KiB
//   over_capacity.img   more training points than the firmware holds

#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "cdcr/model/flash_image.hpp"
#include "export/image_writer.hpp"

#include "../support/synthetic_trained_model.hpp"
#include "../support/v1_image.hpp"

namespace {

void write(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (!file) throw std::runtime_error("cannot write " + path);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_test_image OUT_DIR\n");
    return 2;
  }
  const std::string dir = argv[1];
  try {
    std::filesystem::create_directories(dir);
    using cdcr::test_support::SyntheticModelOptions;
    using cdcr::test_support::synthetic_trained_model;
    const std::vector<std::uint8_t> image = cdcr::exporting::write_image(synthetic_trained_model());
    write(dir + "/model.img", image);
    write(dir + "/model_v1.img", cdcr::test_support::v1_image(synthetic_trained_model()));

    std::vector<std::uint8_t> trailing = image;
    trailing.resize(image.size() + 100, 0xFF);
    write(dir + "/model_trailing.img", trailing);

    write(dir + "/truncated.img", std::vector<std::uint8_t>(image.begin(), image.end() - 10));
    write(dir + "/header_only.img", std::vector<std::uint8_t>(image.begin(), image.begin() + 20));

    std::vector<std::uint8_t> flipped = image;
    std::uint32_t alpha_offset;
    std::memcpy(&alpha_offset, image.data() + cdcr::model::image_field::alpha_offset.offset, 4);
    flipped[alpha_offset + 5] ^= 0xFF;
    write(dir + "/flipped.img", flipped);

    SyntheticModelOptions large;
    large.training_points = 800;
    large.segments = 8;
    write(dir + "/large.img", cdcr::exporting::write_image(synthetic_trained_model(large)));

    SyntheticModelOptions over;
    over.training_points = static_cast<int>(cdcr::model::kMaxTrainingPoints) + 1;
    over.segments = 1;
    write(dir + "/over_capacity.img", cdcr::exporting::write_image(synthetic_trained_model(over)));
  } catch (const std::exception& error) {
    std::fprintf(stderr, "make_test_image: %s\n", error.what());
    return 1;
  }
  return 0;
}
