// docs/usage.md against the real programs' --help: every flag that
// meshstream (each subcommand), meshstream-server and meshstream-client
// show is named in that program's section of usage.md, every option that
// takes a value shows its default (or is one of the few that have none),
// and neither the help texts nor usage.md speak the project's internal
// jargon ("issue I's ordering").
#include <gtest/gtest.h>

#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tests/docs/doc_files.h"

namespace meshstream::docs_testing {
namespace {

struct Program {
  std::string name;     // as usage.md's section heading names it, in backticks
  std::string command;  // binary path plus subcommand
  std::string label;    // for messages: "meshstream encode"
};

std::string binary(const std::string& relative) {
  return std::string(MESHSTREAM_BINARY_DIR) + "/" + relative;
}

std::string help_of(const std::string& command) {
  CommandOutput out = run_command(command + " --help");
  EXPECT_EQ(out.status, 0) << command << " --help failed:\n" << out.text;
  EXPECT_NE(out.text.find("Options:"), std::string::npos) << command << " --help:\n" << out.text;
  return out.text;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// The subcommands CLI11 lists under "Subcommands:".
std::vector<std::string> subcommands(const std::string& help) {
  std::vector<std::string> names;
  bool in_list = false;
  for (const std::string& line : lines_of(help)) {
    if (line.rfind("Subcommands:", 0) == 0) {
      in_list = true;
      continue;
    }
    if (!in_list) continue;
    std::smatch m;
    if (std::regex_search(line, m, std::regex(R"(^  ([a-z][a-z0-9-]*)\s)"))) names.push_back(m[1]);
  }
  return names;
}

// One option of a --help text: its long names (--x) and the rest of its
// line(s) (type, default, description).
struct HelpOption {
  std::vector<std::string> flags;
  std::string details;
};

std::vector<HelpOption> options_of(const std::string& help) {
  std::vector<HelpOption> options;
  bool in_options = false;
  for (const std::string& line : lines_of(help)) {
    if (line.rfind("Options:", 0) == 0) {
      in_options = true;
      continue;
    }
    if (!line.empty() && line[0] != ' ') in_options = false;  // next section
    if (!in_options || line.empty()) continue;
    const size_t start = line.find_first_not_of(' ');
    if (start == std::string::npos) continue;
    if (start == 2 && line[2] == '-') {  // a new option: "  -o,--output TEXT ..."
      HelpOption o;
      const size_t end = line.find(' ', start);
      std::stringstream names(line.substr(start, end - start));
      for (std::string name; std::getline(names, name, ',');) {
        if (name.rfind("--", 0) == 0) o.flags.push_back(name);
      }
      o.details = end == std::string::npos ? "" : line.substr(end);
      options.push_back(o);
    } else if (!options.empty()) {  // the description, wrapped onto its own line
      options.back().details += " " + line.substr(start);
    }
  }
  return options;
}

// The text of the level-2 section of usage.md whose heading names
// `program` in backticks, up to the next level-2 heading.
std::string section_of(const std::string& usage, const std::string& program) {
  std::string section;
  bool inside = false;
  for (const std::string& line : lines_of(usage)) {
    if (line.rfind("## ", 0) == 0) inside = line.find("`" + program + "`") != std::string::npos;
    if (inside) section += line + "\n";
  }
  return section;
}

// `flag` as a whole word in `text`: "--percent" is not "--percent-bytes".
bool mentions(const std::string& text, const std::string& flag) {
  for (size_t at = text.find(flag); at != std::string::npos; at = text.find(flag, at + 1)) {
    const size_t after = at + flag.size();
    const bool ends =
        after >= text.size() || !(std::isalnum(static_cast<unsigned char>(text[after])) ||
                                  text[after] == '-' || text[after] == '_');
    if (ends) return true;
  }
  return false;
}

std::vector<Program> programs() {
  std::vector<Program> list{
      {"meshstream-server", binary("server/meshstream-server"), "meshstream-server"},
      {"meshstream-client", binary("client/meshstream-client"), "meshstream-client"}};
  const std::string tool = binary("tools/meshstream");
  for (const std::string& sub : subcommands(help_of(tool))) {
    list.push_back({"meshstream", tool + " " + sub, "meshstream " + sub});
  }
  return list;
}

std::string usage_md() { return read_text(source_dir() / "docs" / "usage.md"); }

TEST(HelpVsUsage, TheToolListsItsSubcommands) {
  const std::vector<std::string> subs = subcommands(help_of(binary("tools/meshstream")));
  EXPECT_GE(subs.size(), 6u) << "info, encode, decode, subdivide, compare, generate expected";
  const std::string section = section_of(usage_md(), "meshstream");
  ASSERT_FALSE(section.empty()) << "docs/usage.md has no section whose heading names `meshstream`";
  for (const std::string& sub : subs) {
    EXPECT_NE(section.find("meshstream " + sub), std::string::npos)
        << "docs/usage.md does not show `meshstream " << sub << "`";
  }
}

TEST(HelpVsUsage, EveryFlagOfEveryProgramIsInItsSectionOfUsageMd) {
  const std::string usage = usage_md();
  ASSERT_FALSE(usage.empty()) << "docs/usage.md not found";
  std::vector<std::string> missing;
  size_t flags = 0;
  for (const Program& program : programs()) {
    const std::string section = section_of(usage, program.name);
    if (section.empty()) {
      missing.push_back(program.name + ": no section of docs/usage.md names `" + program.name +
                        "` in its heading");
      continue;
    }
    for (const HelpOption& option : options_of(help_of(program.command))) {
      for (const std::string& flag : option.flags) {
        if (flag == "--help") continue;  // every program has it; said once at the top
        ++flags;
        if (!mentions(section, flag)) missing.push_back(program.label + " " + flag);
      }
    }
  }
  EXPECT_GT(flags, 40u) << "the --help parser found too few flags: is it broken?";
  std::string list;
  for (const std::string& m : missing) list += "\n  " + m;
  EXPECT_TRUE(missing.empty()) << missing.size()
                               << " flags missing from their program's section of docs/usage.md "
                                  "(say what each does and its default):"
                               << list;
}

// Options with a value but no default, each for a reason: a required
// input, a file to write, a budget or bound that is off unless given.
const std::set<std::string> kNoDefault = {
    "--output", "--models",   "--out",     "--snapshot",      "--snapshot-at",
    "--bytes",  "--vertices", "--percent", "--percent-bytes", "--ratio",
};

TEST(HelpVsUsage, EveryOptionWithAValueShowsItsDefault) {
  std::vector<std::string> silent;
  for (const Program& program : programs()) {
    for (const HelpOption& option : options_of(help_of(program.command))) {
      if (option.flags.empty()) continue;
      // A flag without a value shows no type (TEXT, INT, UINT, FLOAT, ...).
      // CLI11 writes the type one space after the name; a description
      // starts further right.
      const bool takes_value = std::regex_search(option.details, std::regex("^ [A-Z]"));
      if (!takes_value) continue;
      const bool shows_default = std::regex_search(option.details, std::regex(R"(=\S)")) ||
                                 option.details.find("default") != std::string::npos;
      bool exempt = false;
      for (const std::string& flag : option.flags) exempt |= kNoDefault.count(flag) > 0;
      if (!shows_default && !exempt) silent.push_back(program.label + " " + option.flags[0]);
    }
  }
  std::string list;
  for (const std::string& s : silent) list += "\n  " + s;
  EXPECT_TRUE(silent.empty())
      << silent.size()
      << " options show no default: add ->capture_default_str() (or say \"default ...\" in "
         "the description); an option that has none belongs in "
         "kNoDefault above, with the reason:"
      << list;
}

// "issue I", "issue 5's target": names from the project's tracker mean
// nothing to a user. Flag names are left out of the check (an old name
// kept as an alias is no sentence).
TEST(HelpVsUsage, NoTrackerJargonInHelpOrUsage) {
  const std::regex jargon(R"(\bissues?\b)", std::regex::icase);
  const std::regex flag_name(R"(--[A-Za-z0-9-]+)");
  std::vector<std::string> found;
  for (const Program& program : programs()) {
    for (const std::string& line : lines_of(help_of(program.command))) {
      if (std::regex_search(std::regex_replace(line, flag_name, ""), jargon))
        found.push_back(program.label + " --help: " + line);
    }
  }
  size_t number = 0;
  for (const std::string& line : lines_of(usage_md())) {
    ++number;
    if (std::regex_search(std::regex_replace(line, flag_name, ""), jargon))
      found.push_back("docs/usage.md:" + std::to_string(number) + ": " + line);
  }
  std::string list;
  for (const std::string& f : found) list += "\n  " + f;
  EXPECT_TRUE(found.empty()) << found.size() << " lines speak of issues:" << list;
}

}  // namespace
}  // namespace meshstream::docs_testing
