// One test's own folder under the system's temporary directory.
#pragma once

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <string>
#include <string_view>

namespace sheardiff {

// Named by the running test (and a tag where a test needs two) and by the process, so two test
// processes on one machine (ctest -j2, two CI checkouts) never share one. It is empty when the
// test starts, whatever an earlier run left, and removed when the test ends, also when an
// assertion returned early. A failed test's folder is kept for a look and its path printed; as
// it is named by the process, a later run does not clear it: remove /tmp/sheardiff_* by hand.
// A temporary ScratchDir inside a check's expression is gone before that check fails.
class ScratchDir {
 public:
  explicit ScratchDir(std::string_view tag = "") {
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name =
        fmt::format("sheardiff_{}_{}{}{}_{}", test ? test->test_suite_name() : "",
                    test ? test->name() : "", tag.empty() ? "" : "_", tag, ::getpid());
    std::replace(name.begin(), name.end(), '/', '_');  // parameterised tests' names
    path_ = std::filesystem::temp_directory_path() / name;
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    if (::testing::Test::HasFailure()) {
      std::cerr << "test files kept in " << path_.string() << "\n";
      return;
    }
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  // Implicit, so that a test passes the folder where a path is taken.
  operator const std::filesystem::path&() const { return path_; }
  std::filesystem::path operator/(const std::filesystem::path& p) const { return path_ / p; }

 private:
  std::filesystem::path path_;
};

}  // namespace sheardiff
