#pragma once
// What the dataset readers' rejection tests share: a case (a file's text, the
// line and the exact message the reader must refuse it with), its name in the
// test list, and the refusal a reader gives.

#include <ostream>
#include <string>

#include <gtest/gtest.h>

#include "dataset/csv_dataset.hpp"

namespace cdcr::test_support {

struct RejectionCase {
  const char* name;
  std::string text;
  int line;
  std::string message;  // exact what()
};

inline void PrintTo(const RejectionCase& c, std::ostream* os) { *os << c.name; }

inline std::string rejection_case_name(const testing::TestParamInfo<RejectionCase>& info) { return info.param.name; }

// The refusal names the case's line and gives its message, exactly.
inline void expect_refusal_matches(const dataset::DatasetError& e, const RejectionCase& c) {
  EXPECT_EQ(e.line(), c.line);
  EXPECT_EQ(std::string(e.what()), c.message);
}

// The DatasetError that read() throws for `text`; fails the test if it throws
// none, saying it `outcome` the text.
template <typename Read>
dataset::DatasetError refusal(Read read, const std::string& text, const char* outcome = "accepted") {
  try {
    read();
  } catch (const dataset::DatasetError& e) {
    return e;
  }
  ADD_FAILURE() << outcome << ":\n" << text;
  return dataset::DatasetError(-1, outcome);
}

}  // namespace cdcr::test_support
