// One pneumo at a time per output folder (core/output_lock.h): two runs into one --out once mixed
// their results. Checked: a second lock on a held folder is refused naming it, and succeeds once
// the first is gone; folders the lock created are removed again when nothing was written into
// them; and every writing command refuses (exit 2, one line, the folder untouched) while another
// process holds its --out.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "cli_test_support.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/output_lock.h"
#include "io_test_support.h"
#include "tiny_case_support.h"

namespace pneumo {
namespace {

using testing_support::CliResult;
using testing_support::run_pneumo;
using testing_support::ScratchDir;
using testing_support::tree;
using testing_support::write_tiny_case;
namespace fs = std::filesystem;

TEST(OutputLock, ASecondLockIsRefusedUntilTheFirstIsGone) {
  ScratchDir d;
  const std::string out = d.file("out");
  {
    const OutputFolderLock first(out);
    EXPECT_TRUE(fs::is_directory(out));
    try {
      const OutputFolderLock second(out);
      ADD_FAILURE() << "two locks on one folder";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(out + ": another pneumo is writing into this folder"), std::string::npos)
          << e.what();
    }
  }
  EXPECT_NO_THROW(OutputFolderLock again(out));
}

TEST(OutputLock, FoldersItCreatedGoWhenLeftEmptyAndStayWithResults) {
  ScratchDir d;
  { const OutputFolderLock lock(d.file("a/b/c")); }
  EXPECT_FALSE(fs::exists(d.file("a"))) << "empty folders the lock made were left behind";
  {
    const OutputFolderLock lock(d.file("a/b/c"));
    testing_support::write_bytes(d.file("a/b/c/metrics.json"), "{}\n");
  }
  EXPECT_TRUE(fs::exists(d.file("a/b/c/metrics.json")));
  fs::create_directories(d.file("kept"));
  { const OutputFolderLock lock(d.file("kept")); }
  EXPECT_TRUE(fs::is_directory(d.file("kept"))) << "a folder the lock did not create was removed";
}

TEST(OutputLock, TemporariesAKilledRunLeftAreRemovedByTheNextLockAndNothingElse) {
  // AtomicFile's temporary names, at the top of --out and in a views folder below, as kill -9 leaves
  // them; beside them files that only look alike, which are not pneumo's to remove.
  ScratchDir d;
  fs::create_directories(d.file("out/views"));
  const std::vector<std::string> stale = {"out/.deformed_labels.nii.gz.tmp4242_0.deformed_labels.nii.gz",
                                          "out/views/.port.png.tmp17_3.port.png"};
  const std::vector<std::string> kept = {"out/.hidden", "out/notes.tmp1_2.txt", "out/.a.tmp1_2.b",
                                         "out/.x.tmp_1.x", "out/metrics.json"};
  for (const auto& f : stale) testing_support::write_bytes(d.file(f), "");
  for (const auto& f : kept) testing_support::write_bytes(d.file(f), "{}");
  // The names AtomicFile really gives are the ones recognised.
  const AtomicFile pending(d.file("out/deformed_ct.nii.gz"));
  EXPECT_TRUE(is_atomic_temporary_name(fs::path(pending.temp_path()).filename().string())) << pending.temp_path();
  testing_support::write_bytes(pending.temp_path(), "");
  const OutputFolderLock lock(d.file("out"));
  EXPECT_EQ(lock.removed_temporaries(), 3);
  EXPECT_FALSE(fs::exists(pending.temp_path()));
  for (const auto& f : stale) EXPECT_FALSE(fs::exists(d.file(f))) << f;
  for (const auto& f : kept) EXPECT_TRUE(fs::exists(d.file(f))) << f;
}

TEST(OutputLock, EveryWritingCommandRefusesAFolderAnotherProcessHolds) {
  ScratchDir d;
  const std::string scene = write_tiny_case(d);
  ASSERT_EQ(run_pneumo("-q simulate " + scene + " --out " + d.file("sim")).code, 0);
  const auto before = tree(d.path() / "sim");
  // The lock is held by this process; the commands run as others, as a second user's would.
  const OutputFolderLock held(d.file("sim"));
  for (const char* command : {"simulate", "warp", "render", "run"}) {
    SCOPED_TRACE(command);
    const CliResult r = run_pneumo(std::string("-q ") + command + " " + scene + " --out " + d.file("sim") + " --force");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("another pneumo is writing into this folder"), std::string::npos) << r.err;
    EXPECT_EQ(tree(d.path() / "sim"), before) << "the held folder changed";
  }
}

}  // namespace
}  // namespace pneumo
