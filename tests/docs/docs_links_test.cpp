// A fresh clone must be able to follow every reference in it: no tracked
// file may send the reader to design notes outside the repository (the
// old ../shared/*.md; the shared *meshes* are test data and stay), and
// every relative link of README.md and docs/*.md must name a file (and a
// heading, for #anchors) that exists.
#include <gtest/gtest.h>

#include <cctype>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tests/docs/doc_files.h"

namespace meshstream::docs_testing {
namespace {

// Line number (1-based) of byte `offset` in `text`.
size_t line_of(const std::string& text, size_t offset) {
  return 1 + static_cast<size_t>(std::count(text.begin(), text.begin() + offset, '\n'));
}

TEST(DocsLinks, NoTrackedFilePointsToDesignNotesOutsideTheRepository) {
  // A markdown file directly in a sibling "shared" folder, or the two
  // notes by their upper-case names (the repository's own are
  // docs/design.md and docs/algorithms.md).
  const std::regex outside(R"(shared/[A-Za-z0-9_.-]+\.md|\b(DESIGN|ALGORITHMS)\.md)");
  std::vector<std::string> found;
  const std::vector<std::string> files = tracked_files();
  ASSERT_GT(files.size(), 50u) << "the source tree was not found at " << source_dir();
  for (const std::string& file : files) {
    if (file == "tests/docs/docs_links_test.cpp") continue;  // the pattern itself
    const std::string text = read_text(source_dir() / file);
    if (looks_binary(text)) continue;
    for (auto it = std::sregex_iterator(text.begin(), text.end(), outside);
         it != std::sregex_iterator(); ++it) {
      found.push_back(file + ":" + std::to_string(line_of(text, it->position())) + ": " +
                      it->str());
    }
  }
  std::string list;
  for (const std::string& f : found) list += "\n  " + f;
  EXPECT_TRUE(found.empty()) << found.size()
                             << " references to notes outside the repository (point them at "
                                "docs/design.md or docs/algorithms.md):"
                             << list;
}

// GitHub's anchor for a heading: lower case, punctuation other than '-'
// and '_' dropped, spaces turned into '-'.
std::string anchor_of(const std::string& heading) {
  std::string slug;
  for (unsigned char c : heading) {
    if (std::isalnum(c) || c == '-' || c == '_' || c >= 0x80) {
      slug += static_cast<char>(std::tolower(c));
    } else if (c == ' ') {
      slug += '-';
    }
  }
  return slug;
}

// Every anchor the headings of a markdown text define (a repeated heading
// gets -1, -2, ...). Headings inside fenced code blocks do not count.
std::set<std::string> anchors_in(const std::string& markdown) {
  std::set<std::string> anchors;
  std::istringstream lines(markdown);
  bool in_code = false;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("```", 0) == 0) in_code = !in_code;
    if (in_code || line.empty() || line[0] != '#') continue;
    const size_t text_start = line.find_first_not_of('#');
    if (text_start == std::string::npos || line[text_start] != ' ') continue;
    const std::string base = anchor_of(line.substr(text_start + 1));
    std::string anchor = base;
    for (int n = 1; anchors.count(anchor); ++n) anchor = base + "-" + std::to_string(n);
    anchors.insert(anchor);
  }
  return anchors;
}

// The relative targets of [text](target) and ![alt](target) outside code.
struct Link {
  size_t line;
  std::string target;
};

std::vector<Link> relative_links(const std::string& markdown) {
  std::vector<Link> links;
  const std::regex link(R"(\]\(([^)\s]+)(\s+"[^"]*")?\))");
  std::istringstream lines(markdown);
  bool in_code = false;
  size_t number = 0;
  for (std::string line; std::getline(lines, line);) {
    ++number;
    if (line.rfind("```", 0) == 0) in_code = !in_code;
    if (in_code) continue;
    // Drop inline code spans: `a](b)` there is not a link.
    line = std::regex_replace(line, std::regex("`[^`]*`"), "``");
    for (auto it = std::sregex_iterator(line.begin(), line.end(), link);
         it != std::sregex_iterator(); ++it) {
      const std::string target = (*it)[1].str();
      if (target.find("://") != std::string::npos || target.rfind("mailto:", 0) == 0) continue;
      links.push_back({number, target});
    }
  }
  return links;
}

TEST(DocsLinks, EveryRelativeLinkOfTheReadmeAndDocsResolves) {
  std::vector<std::string> pages{"README.md"};
  for (const std::string& file : tracked_files()) {
    if (file.rfind("docs/", 0) == 0 && file.size() > 3 && file.substr(file.size() - 3) == ".md")
      pages.push_back(file);
  }
  ASSERT_GE(pages.size(), 3u) << "README.md and docs/*.md not found";
  std::vector<std::string> broken;
  size_t checked = 0;
  for (const std::string& page : pages) {
    const fs::path page_path = source_dir() / page;
    const std::string text = read_text(page_path);
    for (const Link& link : relative_links(text)) {
      ++checked;
      const size_t hash = link.target.find('#');
      const std::string file = link.target.substr(0, hash);
      const std::string anchor = hash == std::string::npos ? "" : link.target.substr(hash + 1);
      const fs::path target = file.empty() ? page_path : page_path.parent_path() / file;
      const std::string where = page + ":" + std::to_string(link.line) + ": " + link.target;
      std::error_code ec;
      const fs::path resolved = fs::weakly_canonical(target, ec);
      const fs::path root = fs::weakly_canonical(source_dir());
      if (ec || !fs::exists(resolved)) {
        broken.push_back(where + " (no such file)");
        continue;
      }
      if (resolved.string().rfind(root.string(), 0) != 0) {
        broken.push_back(where + " (outside the repository)");
        continue;
      }
      if (!anchor.empty() && resolved.extension() == ".md" &&
          !anchors_in(read_text(resolved)).count(anchor)) {
        broken.push_back(where + " (no heading with that anchor)");
      }
    }
  }
  EXPECT_GT(checked, 10u) << "the link pattern found almost nothing: is it broken?";
  std::string list;
  for (const std::string& b : broken) list += "\n  " + b;
  EXPECT_TRUE(broken.empty()) << broken.size() << " broken links:" << list;
}

TEST(DocsLinks, AnchorsFollowGithubsRule) {
  EXPECT_EQ(anchor_of("JSON events (`--json`, one object per line on stdout)"),
            "json-events---json-one-object-per-line-on-stdout");
  EXPECT_EQ(anchor_of("1. HCS: one embedded stream"), "1-hcs-one-embedded-stream");
  auto anchors = anchors_in("# A\n## A\n```\n# B\n```\n");
  EXPECT_EQ(anchors, (std::set<std::string>{"a", "a-1"}));
}

}  // namespace
}  // namespace meshstream::docs_testing
