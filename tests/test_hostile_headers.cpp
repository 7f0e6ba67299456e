// Every generated hostile header (hostile_headers.h: 8 formats × 23 sizes × 4 voxel types) is
// refused with one InputError line that starts with the file's name, before anything it promises is
// allocated; `pneumo info` gives exit 2 for one of each format.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <string>

#include "cli_test_support.h"
#include "core/error.h"
#include "hostile_headers.h"
#include "io/volume_io.h"

namespace pneumo {
namespace {

using namespace testing_support;

std::string write_case(const ScratchDir& d, const hostile::HostileFile& f) {
  write_bytes(d.file(f.name), f.bytes);
  if (!f.data_file_name.empty()) write_bytes(d.file(f.data_file_name), f.data_bytes);
  return d.file(f.name);
}

TEST(HostileHeaders, EverySizeInEveryFormatAndTypeIsRefusedNamingTheFile) {
  ScratchDir d;
  const auto files = hostile::hostile_files();
  ASSERT_EQ(files.size(), 8u * 23u * 4u);
  std::map<std::string, int> refused_by_format;
  for (const hostile::HostileFile& f : files) {
    const std::string path = write_case(d, f);
    try {
      const Volume v = read_volume(path);
      ADD_FAILURE() << f.name << ": read " << v.voxel_count() << " voxels";
    } catch (const InputError& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.rfind(path + ": ", 0), 0u) << m;
      EXPECT_EQ(m.find('\n'), std::string::npos) << m;
      ++refused_by_format[f.name.substr(f.name.find('_', f.name.find('_') + 1))];
    } catch (const std::exception& e) {
      ADD_FAILURE() << f.name << ": not an InputError: " << e.what();
    }
  }
  for (const auto& [format, n] : refused_by_format) EXPECT_EQ(n, 23 * 4) << format;
  EXPECT_EQ(refused_by_format.size(), 8u);
}

TEST(HostileHeaders, TheSameFilesWithSizesThatFitAreRead) {
  ScratchDir d;
  for (const hostile::HostileType& t : hostile::hostile_types())
    for (const std::string& format : hostile::hostile_formats()) {
      const auto dims = hostile::fitting_dims(t);
      const hostile::HostileFile f = hostile::hostile_file("fit_" + std::to_string(t.bits), format, dims, t);
      try {
        const Volume v = read_volume(write_case(d, f));
        EXPECT_EQ(v.geometry().dims[2], dims[2]) << f.name;
        EXPECT_EQ(v.byte_count(), hostile::small_payload().size()) << f.name;
      } catch (const std::exception& e) {
        ADD_FAILURE() << f.name << ": " << e.what();
      }
    }
}

TEST(HostileHeaders, InfoExitsTwoWithOneLineForEachFormat) {
  ScratchDir d;
  const hostile::HostileType int16 = hostile::hostile_types()[1];
  for (const std::string& format : hostile::hostile_formats()) {
    // 2^33 voxels promised, 64 bytes held.
    const hostile::HostileFile f = hostile::hostile_file("many", format, {1 << 14, 1 << 14, 1 << 5}, int16);
    const CliResult r = run_pneumo("info " + write_case(d, f));
    EXPECT_EQ(r.code, 2) << f.name << ": " << r.err;
    EXPECT_EQ(r.err.rfind("pneumo: error: " + d.file(f.name) + ": ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
}

}  // namespace
}  // namespace pneumo
