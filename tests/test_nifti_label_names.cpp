// The names a label map carries in its NIfTI header extension (io/nifti_label_names.cpp): read from
// TotalSegmentator's output, and malformed tables refused naming the file.
#include <gtest/gtest.h>

#include <fstream>
#include <map>

#include "core/error.h"
#include "example_roles_support.h"
#include "io/label_table.h"
#include "io/volume_io.h"
#include "io_test_support.h"

using namespace pneumo;
using namespace pneumo::testing_support;

TEST(NiftiLabelNames, TheExampleMapCarriesTotalSegmentatorsNames) {
  PNEUMO_REQUIRE_REAL_CT();
  const std::map<int, std::string> names = read_nifti_label_names(example_labels_path());
  EXPECT_EQ(names, read_label_names(label_table_dir() + "/totalsegmentator_total.csv"));
  EXPECT_TRUE(read_nifti_label_names(example_ct_path()).empty());   // a CT carries none
}

namespace {

/// A 2×2×1 uint8 NIfTI-1 file with `extension` (padded to 16 bytes) after the header.
void write_nifti_with_extension(const std::string& path, const std::string& extension) {
  nifti_1_header h = testing_support::nifti1_test_header(2, 2, 1, NIFTI_TYPE_UINT8, 8);
  const int32_t esize = int32_t((extension.size() + 8 + 15) / 16 * 16);
  h.vox_offset = float(352 + esize);
  std::ofstream f(path, std::ios::binary);
  f.write(reinterpret_cast<const char*>(&h), sizeof h);
  const char flag[4] = {1, 0, 0, 0};
  f.write(flag, 4);
  const int32_t ecode = 0;
  f.write(reinterpret_cast<const char*>(&esize), 4);
  f.write(reinterpret_cast<const char*>(&ecode), 4);
  std::string body = extension;
  body.resize(std::size_t(esize - 8), '\0');
  f.write(body.data(), std::streamsize(body.size()));
  const char voxels[4] = {0, 1, 2, 1};
  f.write(voxels, 4);
}

}  // namespace

TEST(NiftiLabelNames, MalformedTablesAreRefusedNamingTheFile) {
  ScratchDir dir;
  const std::string ok = dir.file("ok.nii");
  write_nifti_with_extension(ok, "<LabelTable>\n<Label Key=\"1\" Red=\"1\"><![CDATA[liver]]></Label>\n"
                                 "<Label Key=\"2\">kidney left</Label></LabelTable>");
  EXPECT_EQ(read_nifti_label_names(ok), (std::map<int, std::string>{{1, "liver"}, {2, "kidney left"}}));
  EXPECT_EQ(read_volume(ok).voxel_count(), 4);   // the volume reader skips the extension

  const std::pair<const char*, const char*> bad[] = {
      {"<LabelTable><Label Key=\"-3\">x</Label></LabelTable>", "Key"},
      {"<LabelTable><Label Key=\"70000\">x</Label></LabelTable>", "Key"},
      {"<LabelTable><Label Red=\"1\">x</Label></LabelTable>", "no Key"},
      {"<LabelTable><Label Key=\"1\">x</Label><Label Key=\"1\">y</Label></LabelTable>", "twice"},
      {"<LabelTable><Label Key=\"1\"><![CDATA[]]></Label></LabelTable>", "empty name"},
      {"<LabelTable><Label Key=\"1\">liver", "cut short"},
  };
  for (const auto& [text, problem] : bad) {
    const std::string path = dir.file("bad.nii");
    write_nifti_with_extension(path, text);
    try {
      read_nifti_label_names(path);
      ADD_FAILURE() << "accepted " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(problem), std::string::npos) << e.what();
    }
  }
  // Another tool's extension (no label table) names nothing.
  const std::string other = dir.file("other.nii");
  write_nifti_with_extension(other, "<CaretExtension><Date>today</Date></CaretExtension>");
  EXPECT_TRUE(read_nifti_label_names(other).empty());
}

