// The fly-through and inflation-preview videos: ffmpeg is installed by scripts/install_deps.sh,
// and an MP4 plays its frames at render.video_fps, every PNG one frame (24 frames once
// played in 0.96 s, at a rate no key could change). Checked with ffprobe, ffmpeg's own reader.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "cli_test_support.h"
#include "image/png.h"
#include "pipeline/render_scene.h"

namespace fs = std::filesystem;
using pneumo::testing_support::run_shell;
using pneumo::testing_support::ScratchDir;

namespace {

// `count` frames of a bar that moves, so that no two frames are the same picture.
void write_frames(const fs::path& dir, int count) {
  fs::create_directories(dir);
  for (int f = 0; f < count; ++f) {
    pneumo::RgbImage im(64, 48, {20, 20, 20});
    for (int y = 0; y < im.height; ++y)
      for (int x = 4 * f; x < 4 * f + 4 && x < im.width; ++x) im.pixel(x, y)[0] = 230;
    char name[32];
    std::snprintf(name, sizeof name, "frame_%04d.png", f + 1);
    pneumo::write_png((dir / name).string(), im);
  }
}

// A word the test's own shell takes as it is: in single quotes, each ' written '\''.
std::string shell_quoted(const std::string& s) {
  std::string q = "'";
  for (const char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// ffprobe's value of one entry (e.g. "stream=nb_read_frames"), as text.
std::string probe(const fs::path& mp4, const std::string& entry) {
  const auto r = run_shell("ffprobe -v error -count_frames -select_streams v:0 -show_entries " + entry +
                           " -of default=noprint_wrappers=1:nokey=1 " + shell_quoted(mp4.string()));
  EXPECT_EQ(r.code, 0) << r.err;
  std::string v = r.out;
  while (!v.empty() && (v.back() == '\n' || v.back() == '\r')) v.pop_back();
  return v;
}

}  // namespace

TEST(Video, FfmpegIsInstalledByTheProjectsScript) {
  ASSERT_TRUE(pneumo::ffmpeg_available()) << "ffmpeg is missing: scripts/install_deps.sh installs it";
  EXPECT_EQ(run_shell("command -v ffprobe").code, 0);
}

TEST(Video, AnMp4PlaysEveryFrameAtTheGivenRate) {
  ASSERT_TRUE(pneumo::ffmpeg_available()) << "ffmpeg is missing: scripts/install_deps.sh installs it";
  ScratchDir d;
  const fs::path frames = fs::path(d.path()) / "path";
  write_frames(frames, 12);
  for (const double fps : {6.0, 25.0}) {
    SCOPED_TRACE(fps);
    const fs::path mp4 = fs::path(d.path()) / ("path_" + std::to_string(int(fps)) + ".mp4");
    ASSERT_TRUE(pneumo::encode_mp4(frames, mp4, fps));
    EXPECT_FALSE(fs::exists(mp4.string() + ".part.mp4"));
    EXPECT_EQ(probe(mp4, "stream=nb_read_frames"), "12");
    EXPECT_EQ(probe(mp4, "stream=r_frame_rate"), std::to_string(int(fps)) + "/1");
    // 12 frames at fps last 12 / fps seconds; the container may round to its time base.
    EXPECT_NEAR(std::stod(probe(mp4, "format=duration")), 12.0 / fps, 0.5 / fps);
  }
}

// The folder's name reaches ffmpeg as it is, never through a shell: a quote, a command substitution,
// a % (image2's pattern character) and a protocol-like prefix are all just characters of the name.
TEST(Video, AFolderNameIsNeverRunOrReinterpreted) {
  ASSERT_TRUE(pneumo::ffmpeg_available()) << "ffmpeg is missing: scripts/install_deps.sh installs it";
  ScratchDir d;
  const fs::path pwned = fs::path(d.path()) / "PWNED";
  const std::vector<std::string> names = {"O'Brien", "x'$(touch " + pwned.string() + ")'",
                                          "100% lap; `touch " + pwned.string() + "`", "http:"};
  for (const std::string& name : names) {
    SCOPED_TRACE(name);
    const fs::path folder = fs::path(d.path()) / name;
    write_frames(folder / "path", 3);
    const fs::path mp4 = folder / "path.mp4";
    ASSERT_TRUE(pneumo::encode_mp4(folder / "path", mp4, 6.0));
    EXPECT_EQ(probe(mp4, "stream=nb_read_frames"), "3");
  }
  EXPECT_FALSE(fs::exists(pwned)) << "a shell ran the folder's name";
}
