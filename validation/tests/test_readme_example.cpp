// The README's "Validate your own sampler" prints a consumer project: examples/consumer/CMakeLists.txt and
// examples/consumer/my_sampler_test.cpp, which the tests consumer.install and consumer.add_subdirectory configure,
// build and run from outside this tree. These tests check that the README prints exactly those files, and links
// every other example.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace {

std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

const std::filesystem::path kSource = WARPCHECK_SOURCE_DIR;

}  // namespace

TEST(ReadmeExample, PrintsTheConsumerProjectsTestVerbatim) {
  const std::string example = slurp(kSource / "examples/consumer/my_sampler_test.cpp");
  ASSERT_FALSE(example.empty());
  EXPECT_NE(slurp(kSource / "README.md").find("```cpp\n" + example + "```"), std::string::npos)
      << "README.md must contain, in a ```cpp block, exactly examples/consumer/my_sampler_test.cpp";
  int lines = 0;
  for (char c : example) lines += c == '\n';
  EXPECT_LE(lines, 30) << "the README's first example stays at most 30 lines";
}

TEST(ReadmeExample, PrintsTheConsumerProjectsCMakeListsVerbatim) {
  const std::string cmake = slurp(kSource / "examples/consumer/CMakeLists.txt");
  ASSERT_FALSE(cmake.empty());
  EXPECT_NE(slurp(kSource / "README.md").find("```cmake\n" + cmake + "```"), std::string::npos)
      << "README.md must contain, in a ```cmake block, exactly examples/consumer/CMakeLists.txt";
}

TEST(ReadmeExample, LinksEveryOtherExample) {
  const std::string readme = slurp(kSource / "README.md");
  for (const auto& e : std::filesystem::directory_iterator(kSource / "examples")) {
    if (e.path().extension() != ".cpp") continue;
    EXPECT_NE(readme.find("(examples/" + e.path().filename().string() + ")"), std::string::npos)
        << "README.md must link examples/" << e.path().filename().string();
  }
}
