// The MCAP writer's file handling: the recording appears under its name
// only when it is complete, a writer that is not closed leaves nothing, and
// a path it cannot write is refused in one line. What the file holds is
// checked by the reference reader (view.mcap_recording).

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "test_work_dir.hpp"
#include "view/mcap_writer.hpp"

namespace {

using cdcr::view::McapWriter;
namespace fs = std::filesystem;

std::string read_all(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(McapWriter, TheFileAppearsWhenClosedWithMagicAtBothEnds) {
  const fs::path dir = cdcr::test_support::fresh_test_work_dir();
  const fs::path path = dir / "run.mcap";
  McapWriter writer(path.string());
  const auto schema = writer.add_schema("cdcr.Test", "jsonschema", R"({"type":"object"})");
  const auto channel = writer.add_channel(schema, "/test", "json");
  writer.write_message(channel, 5, R"({"a":1})");
  EXPECT_FALSE(fs::exists(path));
  EXPECT_TRUE(fs::exists(path.string() + ".tmp"));
  writer.close();
  EXPECT_FALSE(fs::exists(path.string() + ".tmp"));
  const std::string bytes = read_all(path);
  const std::string magic("\x89MCAP0\r\n", 8);
  ASSERT_GT(bytes.size(), 2 * magic.size());
  EXPECT_EQ(bytes.substr(0, 8), magic);
  EXPECT_EQ(bytes.substr(bytes.size() - 8), magic);
  EXPECT_EQ(writer.message_count(), 1u);
}

TEST(McapWriter, AWriterNotClosedLeavesNoFile) {
  const fs::path dir = cdcr::test_support::fresh_test_work_dir();
  const fs::path path = dir / "run.mcap";
  {
    McapWriter writer(path.string());
    writer.add_schema("cdcr.Test", "jsonschema", "{}");
  }
  EXPECT_FALSE(fs::exists(path));
  EXPECT_FALSE(fs::exists(path.string() + ".tmp"));
}

TEST(McapWriter, AnUnwritablePathIsRefusedInOneLine) {
  const fs::path dir = cdcr::test_support::fresh_test_work_dir();
  try {
    McapWriter writer((dir / "missing" / "run.mcap").string());
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("cannot write"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

TEST(McapWriter, UnknownSchemasAndChannelsAreRefused) {
  const fs::path dir = cdcr::test_support::fresh_test_work_dir();
  McapWriter writer((dir / "run.mcap").string());
  EXPECT_THROW(writer.add_channel(1, "/test", "json"), std::invalid_argument);
  EXPECT_THROW(writer.write_message(1, 0, "{}"), std::invalid_argument);
}

}  // namespace
