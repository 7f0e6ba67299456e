// The project documents itself: the README stays short enough
// to read in minutes, every link in it and in docs/ leads to a file of the repository, and every
// "method.md §N" the code cites is a section of docs/method.md.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
const fs::path kRoot = PNEUMO_SOURCE_DIR;

std::string read(const fs::path& p) {
  std::ifstream is(p, std::ios::binary);
  std::stringstream ss;
  ss << is.rdbuf();
  return ss.str();
}

/// The Markdown pages a reader reaches from the README.
std::vector<fs::path> pages() {
  std::vector<fs::path> out = {kRoot / "README.md"};
  for (const auto& e : fs::directory_iterator(kRoot / "docs"))
    if (e.path().extension() == ".md") out.push_back(e.path());
  return out;
}

TEST(Docs, TheReadmeIsShortAndHoldsTheTwoCommands) {
  const std::string readme = read(kRoot / "README.md");
  EXPECT_LE(readme.size(), 10000u) << "README.md is for a newcomer; move detail into docs/";
  EXPECT_NE(readme.find("bash scripts/demo.sh"), std::string::npos);
  EXPECT_NE(readme.find("bash scripts/test.sh"), std::string::npos);
}

TEST(Docs, EveryRelativeLinkLeadsToAFileOfTheRepository) {
  const std::regex link(R"(\]\(([^)\s]+)\))");
  const fs::path root = fs::weakly_canonical(kRoot);
  int checked = 0;
  for (const fs::path& page : pages()) {
    const std::string text = read(page);
    for (std::sregex_iterator it(text.begin(), text.end(), link), end; it != end; ++it) {
      std::string target = (*it)[1];
      if (std::regex_search(target, std::regex("^[a-z]+:")) || target[0] == '#') continue;   // URLs, anchors
      target = target.substr(0, target.find('#'));
      const fs::path resolved = fs::weakly_canonical(page.parent_path() / target);
      const std::string rel = fs::relative(resolved, root).string();
      EXPECT_TRUE(rel.rfind("..", 0) != 0) << page.filename() << " links outside the repository: " << target;
      EXPECT_TRUE(fs::exists(resolved)) << page.filename() << " links to a missing file: " << target;
      ++checked;
    }
  }
  EXPECT_GT(checked, 20) << "the link pattern found almost nothing";
}

TEST(Docs, EverySectionTheCodeCitesExists) {
  std::set<std::string> sections;
  const std::string method = read(kRoot / "docs/method.md");
  const std::regex heading(R"((^|\n)## (\d+)\.)");
  for (std::sregex_iterator it(method.begin(), method.end(), heading), end; it != end; ++it) sections.insert((*it)[2]);
  ASSERT_GE(sections.size(), 10u);
  const std::regex cite(R"(method\.md §(\d+))");
  int cited = 0;
  for (const char* dir : {"host", "render", "kernels", "shaders", "docs"})
    for (const auto& e : fs::recursive_directory_iterator(kRoot / dir)) {
      if (!e.is_regular_file()) continue;
      const std::string text = read(e.path());
      for (std::sregex_iterator it(text.begin(), text.end(), cite), end; it != end; ++it) {
        EXPECT_TRUE(sections.count((*it)[1])) << e.path() << " cites method.md §" << (*it)[1] << ", which docs/method.md lacks";
        ++cited;
      }
    }
  EXPECT_GT(cited, 20) << "the citation pattern found almost nothing";
}

}  // namespace
