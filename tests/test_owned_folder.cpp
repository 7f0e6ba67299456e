// A forced run replaces an earlier run's results, and only those: the folders pneumo fills below --out
// (views/, flythrough/, timelapse/) are marked when pneumo makes them, and a folder of the user's that
// shares such a name is refused, never removed (core/owned_folder.h).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "cli_test_support.h"
#include "core/error.h"
#include "core/owned_folder.h"
#include "io_test_support.h"
#include "phantom/phantom.h"

using namespace pneumo;
using testing_support::ScratchDir;
namespace fs = std::filesystem;

TEST(OwnedFolder, OnlyAFolderPneumoMadeIsRemoved) {
  ScratchDir d;
  const fs::path mine = d.file("views"), theirs = d.file("theirs");
  create_owned_folder(mine);
  std::ofstream(mine / "port.png") << "png";
  EXPECT_TRUE(is_owned_folder(mine));
  fs::create_directories(theirs);
  std::ofstream(theirs / "holiday.jpg") << "jpg";
  EXPECT_FALSE(is_owned_folder(theirs));
  EXPECT_THROW(check_owned_or_absent(theirs), InputError);
  EXPECT_THROW(create_owned_folder(theirs), InputError);
  EXPECT_FALSE(remove_owned_folder(theirs));
  EXPECT_TRUE(fs::exists(theirs / "holiday.jpg"));
  EXPECT_TRUE(remove_owned_folder(mine));
  EXPECT_FALSE(fs::exists(mine));
  EXPECT_NO_THROW(check_owned_or_absent(mine));   // absent: pneumo may make it
}

TEST(OwnedFolder, AnEmptyFolderIsTakenAndMarked) {
  // A run killed between making views/ and marking it leaves it empty (the full test suite caught
  // one: KillDuringRun). Nothing in it can be lost, so the next run takes it; one hidden file of the
  // user's makes it theirs again.
  ScratchDir d;
  const fs::path empty = d.file("views"), hidden = d.file("flythrough");
  fs::create_directories(empty);
  EXPECT_NO_THROW(check_owned_or_absent(empty));
  create_owned_folder(empty);
  EXPECT_TRUE(is_owned_folder(empty));
  fs::create_directories(hidden);
  std::ofstream(hidden / ".notes") << "mine";
  EXPECT_THROW(check_owned_or_absent(hidden), InputError);
}

TEST(OwnedFolder, ALinkToAUsersFolderIsNotPneumos) {
  // The marker is looked for in the folder itself, not through a link to another one that has it.
  ScratchDir d;
  create_owned_folder(d.file("real"));
  fs::create_directory_symlink(d.file("real"), d.file("views"));
  EXPECT_FALSE(is_owned_folder(d.file("views")));
  EXPECT_FALSE(remove_owned_folder(d.file("views")));
  EXPECT_TRUE(fs::exists(d.file("real")));
}

TEST(OwnedFolder, RunForceLeavesAUsersViewsFolderAsItWas) {
  // `pneumo run --force` into a folder holding the user's own views/ (with an earlier run's report
  // beside it): refused with exit 2 naming the folder, before any work, and the user's files stay.
  ScratchDir d;
  write_phantom_case(make_phantom(PhantomSize::Small), PhantomSize::Small, d.path().string());
  const fs::path out = d.file("run");
  fs::create_directories(out / "views");
  std::ofstream(out / "views" / "my_notes.txt") << "mine";
  std::ofstream(out / "report.html") << "earlier";
  const auto r = testing_support::run_pneumo("-q run " + d.file("scene.json") + " --out " + out.string() + " --force");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("views"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("not a folder pneumo made"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(out / "views" / "my_notes.txt"));
  EXPECT_TRUE(fs::exists(out / "report.html"));
}
