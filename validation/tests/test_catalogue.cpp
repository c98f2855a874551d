// One name per kernel: the battery's registry, the worst-case searches, the stored benchmark results and the fuzz
// targets' folders name kernels only by lib/warpcheck/catalogue.h's names, and every catalogue kernel is in the
// battery.
#include <gtest/gtest.h>

#include <boost/json.hpp>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "warpcheck/catalogue.h"
#include "warpcheck/validation/registry.h"
#include "warpcheck/validation/searches.h"

namespace {

namespace fs = std::filesystem;
using warpcheck::AllKernels;

bool in_catalogue(const std::string& name) { return AllKernels::contains(name); }

bool starts_with(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }
bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// The kernel a worst-case search is about: precision-KERNEL-{float,double}-{angle,backward} or pdf-warp-KERNEL;
// nullopt for the searches about something else (polygon-backward-*, projected-cap-*, sptd-cap-invariance).
std::optional<std::string> kernel_of_search(const std::string& search) {
  if (starts_with(search, "pdf-warp-")) return search.substr(9);
  if (!starts_with(search, "precision-")) return std::nullopt;
  for (const char* scalar : {"-float", "-double"})
    for (const char* metric : {"-angle", "-backward"}) {
      const std::string tail = std::string(scalar) + metric;
      if (ends_with(search, tail)) return search.substr(10, search.size() - 10 - tail.size());
    }
  return search.substr(10);  // not of the form above: the whole rest, which names no kernel
}

// The kernel a benchmark measures: KERNEL/SCALAR/CONFIG/spl=S[/batch]; "baseline" is the papers' baseline (reads the
// random numbers and the geometry only), no kernel.
std::optional<std::string> kernel_of_benchmark(const std::string& benchmark) {
  const std::string head = benchmark.substr(0, benchmark.find('/'));
  if (head == "baseline") return std::nullopt;
  return head;
}

// The kernel a fuzz target's folder is for: fuzz_KERNEL_{float,double}.
std::string kernel_of_fuzz_folder(const std::string& folder) {
  std::string k = starts_with(folder, "fuzz_") ? folder.substr(5) : folder;
  for (const char* scalar : {"_float", "_double"})
    if (ends_with(k, scalar)) return k.substr(0, k.size() - std::string(scalar).size());
  return k;
}

std::vector<std::string> benchmark_names(const fs::path& file) {
  std::ifstream in(file);
  std::ostringstream text;
  text << in.rdbuf();
  const boost::json::value json = boost::json::parse(text.str());
  std::vector<std::string> names;
  for (const auto& b : json.at("benchmarks").as_array()) names.emplace_back(b.at("name").as_string());
  return names;
}

const fs::path kData = fs::path(WARPCHECK_SOURCE_DIR) / "data";

TEST(Catalogue, NamesAreUniqueAndTheChecksRejectANameOfAnotherLayer) {
  const auto names = AllKernels::names();
  EXPECT_EQ(std::set<std::string_view>(names.begin(), names.end()).size(), names.size());
  // The old names of the kernels in other layers are no catalogue names, and each check below sees them.
  EXPECT_FALSE(in_catalogue("ltc-polygon"));
  EXPECT_FALSE(in_catalogue(*kernel_of_search("pdf-warp-sptd-cap")));
  EXPECT_FALSE(in_catalogue(*kernel_of_search("precision-ltc-polygon-float-angle")));
  EXPECT_FALSE(in_catalogue(*kernel_of_benchmark("sphere_solid_angle/float/qz=2/spl=1")));
  EXPECT_FALSE(in_catalogue(kernel_of_fuzz_folder("fuzz_spherical_rectangle_double")));
  EXPECT_TRUE(in_catalogue(*kernel_of_search("precision-polygon-ltc-double-backward")));
  EXPECT_TRUE(in_catalogue(*kernel_of_benchmark("sphere-solid-angle/float/qz=2/spl=500/batch")));
  EXPECT_TRUE(in_catalogue(kernel_of_fuzz_folder("fuzz_baseline-urena-rectangle_float")));
}

TEST(Catalogue, TheBatteryRegistersEveryKernelAndOnlyCatalogueKernels) {
  std::set<std::string> registered;
  const warpcheck::validation::Registry registry = warpcheck::validation::default_registry();
  for (const warpcheck::validation::Case& c : registry.cases()) {
    EXPECT_TRUE(in_catalogue(c.kernel)) << c.kernel << " " << c.config;
    registered.insert(c.kernel);
  }
  for (std::string_view k : AllKernels::names()) EXPECT_TRUE(registered.count(std::string(k))) << k;
}

TEST(Catalogue, TheSearchesNameOnlyCatalogueKernels) {
  int kernel_searches = 0;
  for (const warpcheck::validation::Search& s : warpcheck::validation::all_searches())
    if (const auto k = kernel_of_search(s.name)) {
      EXPECT_TRUE(in_catalogue(*k)) << s.name;
      ++kernel_searches;
    }
  EXPECT_GT(kernel_searches, 0);
}

TEST(Catalogue, TheStoredBenchmarksNameOnlyCatalogueKernels) {
  int files = 0;
  for (const auto& e : fs::directory_iterator(kData / "bench")) {
    if (e.path().extension() != ".json") continue;
    ++files;
    for (const std::string& b : benchmark_names(e.path())) {
      if (const auto k = kernel_of_benchmark(b)) {
        EXPECT_TRUE(in_catalogue(*k)) << e.path().filename() << ": " << b;
      }
    }
  }
  EXPECT_GT(files, 0);
}

TEST(Catalogue, TheFuzzTargetsFoldersNameOnlyCatalogueKernels) {
  int folders = 0;
  for (const auto& e : fs::directory_iterator(kData / "fuzz")) {
    if (!e.is_directory()) continue;
    const std::string folder = e.path().filename().string();
    ++folders;
    EXPECT_TRUE(starts_with(folder, "fuzz_") && (ends_with(folder, "_float") || ends_with(folder, "_double")))
        << folder;
    EXPECT_TRUE(in_catalogue(kernel_of_fuzz_folder(folder))) << folder;
  }
  EXPECT_GT(folders, 0);
}

}  // namespace
