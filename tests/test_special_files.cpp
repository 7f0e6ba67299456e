// Nothing run that the user did not ask for: every input pneumo reads is a regular file
// (core/input_file.h). A FIFO given as a scene, a CT or a NRRD's data file made pneumo wait forever;
// a link to /dev/zero as the scene grew to gigabytes (the 16 MB cap was skipped when the size could
// not be read). Each is now refused at once: exit 2, one line naming the file and what it is. Every
// child runs under a time limit (and, where no sanitizer maps terabytes, an address-space limit), so
// a reader that still waits or reads without end fails its test instead of hanging the suite.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <functional>
#include <string>

#include "cli_test_support.h"
#include "sanitizer_support.h"
#include "core/error.h"
#include "core/input_file.h"
#include "io/label_table.h"
#include "io/volume_io.h"
#include "mesh/deformation_file.h"
#include "mesh/mesh.h"
#include "tiny_case_support.h"

namespace pneumo {
namespace {

using namespace testing_support;

/// `pneumo ARGS` within 20 s and, without a sanitizer, 4 GB of address space: a reader that waits
/// on a FIFO is killed (exit 124), one that reads /dev/zero without end runs out (not exit 2).
CliResult run_bounded(const std::string& args) {
  const std::string limit = kAddressSanitizer ? "" : "ulimit -v 4000000; ";
  return run_shell(limit + "timeout -k 5 20 " + PNEUMO_CLI_PATH + " " + args);
}

void make_fifo(const std::string& path) { ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0) << path; }

void expect_refused(const CliResult& r, const std::string& path, const std::string& what) {
  EXPECT_EQ(r.code, 2) << "124 or 137: it waited (killed by the time limit); " << r.err;
  EXPECT_EQ(count_occurrences(r.err, "\n"), 1) << "one line: " << r.err;
  EXPECT_NE(r.err.find(path), std::string::npos) << "names the file: " << r.err;
  EXPECT_NE(r.err.find(what), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

TEST(SpecialFiles, ASceneThatIsAFifoOrALinkToDevZeroIsRefusedAtOnce) {
  ScratchDir d;
  make_fifo(d.file("fifo.json"));
  expect_refused(run_bounded("scene " + d.file("fifo.json")), d.file("fifo.json"), "is a FIFO (named pipe)");
  std::filesystem::create_symlink("/dev/zero", d.file("zero.json"));
  expect_refused(run_bounded("scene " + d.file("zero.json")), d.file("zero.json"), "is a device");
  // Through the commands that read a scene, too.
  expect_refused(run_bounded("-q simulate " + d.file("fifo.json") + " --out " + d.file("out")), d.file("fifo.json"),
                 "is a FIFO");
  EXPECT_FALSE(std::filesystem::exists(d.file("out")));
}

TEST(SpecialFiles, ACtThatIsAFifoOrALinkToDevZeroIsRefusedInEveryFormat) {
  ScratchDir d;
  for (const char* name : {"ct.nii", "ct.nii.gz", "ct.mha", "ct.mhd", "ct.nrrd", "ct.nhdr"}) {
    SCOPED_TRACE(name);
    make_fifo(d.file(std::string("fifo_") + name));
    expect_refused(run_bounded("info " + d.file(std::string("fifo_") + name)), d.file(std::string("fifo_") + name),
                   "is a FIFO");
    std::filesystem::create_symlink("/dev/zero", d.file(std::string("zero_") + name));
    expect_refused(run_bounded("info " + d.file(std::string("zero_") + name)), d.file(std::string("zero_") + name),
                   "is a device");
  }
}

TEST(SpecialFiles, ADataFileBesideItsHeaderThatIsAFifoIsRefused) {
  ScratchDir d;
  const std::string nrrd_header =
      "NRRD0004\ntype: short\ndimension: 3\nsizes: 4 4 4\nspace: left-posterior-superior\n"
      "space directions: (1,0,0) (0,1,0) (0,0,1)\nspace origin: (0,0,0)\nencoding: raw\nendian: little\n";
  make_fifo(d.file("data.raw"));
  write_bytes(d.file("one.nhdr"), nrrd_header + "data file: data.raw\n");
  expect_refused(run_bounded("info " + d.file("one.nhdr")), d.file("data.raw"), "is a FIFO");
  // The two other ways a detached header names its data: a list, and a numbered pattern.
  write_bytes(d.file("slice1.raw"), std::string(32, '\0'));
  write_bytes(d.file("list.nhdr"), nrrd_header + "data file: LIST 2\nslice1.raw\ndata.raw\n");
  expect_refused(run_bounded("info " + d.file("list.nhdr")), d.file("data.raw"), "is a FIFO");
  for (int s = 0; s < 4; ++s)
    if (s != 2) write_bytes(d.file("s" + std::to_string(s) + ".raw"), std::string(32, '\0'));
  make_fifo(d.file("s2.raw"));
  write_bytes(d.file("pattern.nhdr"), nrrd_header + "data file: s%d.raw 0 3 1 2\n");
  expect_refused(run_bounded("info " + d.file("pattern.nhdr")), d.file("s2.raw"), "is a FIFO");
  // MetaImage's data file.
  write_bytes(d.file("ct.mhd"), "ObjectType = Image\nNDims = 3\nDimSize = 4 4 4\nElementType = MET_SHORT\n"
                                "ElementDataFile = data.raw\n");
  expect_refused(run_bounded("info " + d.file("ct.mhd")), "data.raw", "is a FIFO");
}

/// `body` in a child process killed after 20 s: true when it threw an InputError holding `says`.
/// (Before the check, these readers waited on the FIFO forever; the limit fails the test instead.)
bool refuses_within_20_s(const std::function<void()>& body, const std::string& says) {
  const pid_t pid = fork();
  if (pid == 0) {
    alarm(20);
    try {
      body();
    } catch (const InputError& e) {
      _exit(std::string(e.what()).find(says) != std::string::npos ? 0 : 3);
    } catch (...) {
      _exit(4);
    }
    _exit(5);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  EXPECT_FALSE(WIFSIGNALED(status) && WTERMSIG(status) == SIGALRM) << "it waited on the FIFO";
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

TEST(SpecialFiles, LabelNamesADeformationAndMetricsThatAreFifosAreRefused) {
  ScratchDir d;
  make_fifo(d.file("names.csv"));
  EXPECT_TRUE(refuses_within_20_s([&] { read_label_names(d.file("names.csv")); }, "names.csv: the label names is a FIFO"));
  make_fifo(d.file("deformation.bin"));
  EXPECT_TRUE(refuses_within_20_s([&] { read_deformation(d.file("deformation.bin"), Mesh{}); },
                                  "deformation.bin: the deformation is a FIFO"));
  std::filesystem::create_symlink("/dev/zero", d.file("zero.csv"));
  EXPECT_TRUE(refuses_within_20_s([&] { read_label_names(d.file("zero.csv")); }, "is a device"));
}

TEST(SpecialFiles, TheCheckNamesEachKindAndReadsARegularFileThroughALink) {
  ScratchDir d;
  write_bytes(d.file("real.txt"), "text");
  std::filesystem::create_symlink(d.file("real.txt"), d.file("link.txt"));
  std::filesystem::create_symlink(d.file("gone.txt"), d.file("dangling.txt"));
  std::filesystem::create_symlink(d.file("loop.txt"), d.file("loop.txt"));
  make_fifo(d.file("fifo"));
  EXPECT_EQ(read_input_file(d.file("link.txt"), 16, "the file", "a test"), "text");
  EXPECT_EQ(probe_file(d.file("link.txt")).kind, FileKind::Regular);
  EXPECT_EQ(probe_file(d.file("dangling.txt")).kind, FileKind::DanglingLink);
  EXPECT_EQ(probe_file(d.file("loop.txt")).kind, FileKind::LinkLoop);
  EXPECT_EQ(probe_file(d.file("fifo")).kind, FileKind::Fifo);
  EXPECT_EQ(probe_file("/dev/null").kind, FileKind::Device);
  EXPECT_EQ(probe_file(d.file("nowhere")).kind, FileKind::Missing);
  EXPECT_EQ(probe_file(d.path().string()).kind, FileKind::Folder);
  try {
    InputFile f(d.file("dangling.txt"), "the CT");
    FAIL() << "a dangling link was opened";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), (d.file("dangling.txt") + ": the CT is a symbolic link to \"" + d.file("gone.txt") +
                            "\", which does not exist: fix or remove the link")
                               .c_str());
  }
  // The cap holds while reading, whatever the size said.
  EXPECT_THROW(read_input_file(d.file("real.txt"), 3, "the file", "a test"), InputError);
}

}  // namespace
}  // namespace pneumo
