// The layers held: every #include of the project's code is checked against the
// tables of docs/architecture.md (which folder may include which, and where
// LCM's generated types, LCM's C API and Qt may appear). A back edge fails here.

#include <fnmatch.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace nadir::architecture {
namespace {

namespace fs = std::filesystem;

// One row of a table: a pattern and the patterns it allows.
struct Row {
  std::string pattern;
  std::vector<std::string> allowed;
};

struct Rules {
  std::vector<Row> layers;   // files -> may include
  std::vector<Row> headers;  // header -> only in
};

// One #include of a file: "quoted" or <angled>.
struct Include {
  std::string file;  // the including file, relative to the source root
  std::string header;
  bool angled = false;
  int line = 0;
};

std::vector<std::string> segments(const std::string& path) {
  std::vector<std::string> parts;
  std::stringstream in(path);
  for (std::string part; std::getline(in, part, '/');) parts.push_back(part);
  return parts;
}

// A pattern ending in '/' is a folder (matching everything under it); '*' in a
// segment matches within that segment. On a match, the path's first segments
// that the pattern covered (its instance: nodes/ppa/ for nodes/*/) are returned.
std::optional<std::string> match(const std::string& pattern, const std::string& path) {
  const bool folder = !pattern.empty() && pattern.back() == '/';
  const std::vector<std::string> want = segments(pattern);
  const std::vector<std::string> have = segments(path);
  if (have.size() < want.size() + (folder ? 1 : 0)) return std::nullopt;
  if (!folder && have.size() != want.size()) return std::nullopt;
  std::string instance;
  for (std::size_t i = 0; i < want.size(); ++i) {
    if (fnmatch(want[i].c_str(), have[i].c_str(), 0) != 0) return std::nullopt;
    instance += have[i] + (folder || i + 1 < want.size() ? "/" : "");
  }
  return instance;
}

// The most specific row for a path (more segments, then a file over a folder),
// and its instance.
std::optional<std::pair<const Row*, std::string>> rowOf(const std::vector<Row>& rows,
                                                         const std::string& path) {
  std::optional<std::pair<const Row*, std::string>> best;
  const auto rank = [](const std::string& pattern) {
    return std::make_pair(segments(pattern).size(), pattern.back() != '/');
  };
  for (const Row& row : rows) {
    if (const auto instance = match(row.pattern, path)) {
      if (!best || rank(row.pattern) > rank(best->first->pattern)) best = {{&row, *instance}};
    }
  }
  return best;
}

// The rows between "<!-- NAME: begin -->" and "<!-- NAME: end -->": the first
// cell's backticked pattern, then every backticked pattern of the second cell.
std::vector<Row> readTable(const std::string& text, const std::string& name) {
  const std::string begin = "<!-- " + name + ": begin -->";
  const std::string end = "<!-- " + name + ": end -->";
  const auto from = text.find(begin);
  const auto to = text.find(end);
  if (from == std::string::npos || to == std::string::npos) return {};
  std::vector<Row> rows;
  std::stringstream in(text.substr(from + begin.size(), to - from - begin.size()));
  const std::regex ticked("`([^`]+)`");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("|", 0) != 0) continue;
    const auto second_bar = line.find('|', 1);
    const std::string first = line.substr(1, second_bar - 1);
    const std::string rest = line.substr(second_bar + 1);
    std::smatch m;
    if (!std::regex_search(first, m, ticked)) continue;  // the header and the --- line
    Row row{m[1], {}};
    for (auto it = std::sregex_iterator(rest.begin(), rest.end(), ticked);
         it != std::sregex_iterator(); ++it) {
      row.allowed.push_back((*it)[1]);
    }
    rows.push_back(row);
  }
  return rows;
}

std::string readText(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

Rules readRules(const fs::path& architecture_md) {
  const std::string text = readText(architecture_md);
  return {readTable(text, "layering table"), readTable(text, "header table")};
}

// A header-table pattern: <lcm/...> and <Q...> are prefixes of angled includes,
// nadir/*.hpp a glob of quoted ones.
bool headerMatches(const std::string& pattern, const Include& include) {
  if (pattern.front() == '<') {
    if (!include.angled) return false;
    std::string prefix = pattern.substr(1, pattern.size() - 2);
    if (prefix.size() >= 3 && prefix.compare(prefix.size() - 3, 3, "...") == 0) {
      prefix.resize(prefix.size() - 3);
    }
    return include.header.rfind(prefix, 0) == 0;
  }
  return !include.angled && fnmatch(pattern.c_str(), include.header.c_str(), 0) == 0;
}

// Every include the rules do not allow, as "file:line: includes header (why)".
std::vector<std::string> violations(const Rules& rules, const std::vector<Include>& includes,
                                    const std::function<bool(const std::string&)>& is_project) {
  std::vector<std::string> found;
  for (const Include& include : includes) {
    const std::string where =
        include.file + ":" + std::to_string(include.line) + ": includes " + include.header;
    for (const Row& header : rules.headers) {
      if (!headerMatches(header.pattern, include)) continue;
      const bool allowed = std::any_of(header.allowed.begin(), header.allowed.end(),
                                       [&](const std::string& place) {
                                         return match(place, include.file).has_value();
                                       });
      if (!allowed) found.push_back(where + " (only in the places docs/architecture.md names)");
    }
    if (include.angled || !is_project(include.header)) continue;
    const auto from = rowOf(rules.layers, include.file);
    if (!from) {
      found.push_back(where + " (" + include.file + " is in no layer of docs/architecture.md)");
      continue;
    }
    const auto to = rowOf(rules.layers, include.header);
    if (to && to->first == from->first && to->second == from->second) continue;  // own layer
    const auto& allowed = from->first->allowed;
    if (std::none_of(allowed.begin(), allowed.end(), [&](const std::string& pattern) {
          return match(pattern, include.header).has_value();
        })) {
      found.push_back(where + " (" + from->first->pattern + " may not include it)");
    }
  }
  return found;
}

// Every #include of the project's C++ files outside tests/ and build folders.
std::vector<Include> projectIncludes(const fs::path& root) {
  std::vector<Include> includes;
  const std::regex directive(R"(^\s*#\s*include\s*([<"])([^>"]+)[>"])");
  for (auto it = fs::recursive_directory_iterator(root); it != fs::recursive_directory_iterator();
       ++it) {
    const std::string rel = fs::relative(it->path(), root).string();
    if (it->is_directory() &&
        (rel == "tests" || rel == ".git" || rel.rfind("build", 0) == 0)) {
      it.disable_recursion_pending();
      continue;
    }
    const std::string extension = it->path().extension().string();
    if (!it->is_regular_file() || (extension != ".cpp" && extension != ".h")) continue;
    std::ifstream in(it->path());
    int number = 0;
    for (std::string line; std::getline(in, line);) {
      ++number;
      std::smatch m;
      if (std::regex_search(line, m, directive)) {
        includes.push_back({rel, m[2], m[1] == "<", number});
      }
    }
  }
  return includes;
}

class Layering : public ::testing::Test {
 protected:
  const fs::path root_ = NADIR_SOURCE_DIR;
  const Rules rules_ = readRules(root_ / "docs" / "architecture.md");
};

// The tables are there and every layer they name is a folder or file of the project.
TEST_F(Layering, TablesNameTheProjectsFolders) {
  ASSERT_GE(rules_.layers.size(), 10u);
  ASSERT_EQ(rules_.headers.size(), 3u);
  for (const Row& row : rules_.layers) {
    const std::string first = segments(row.pattern).front();
    EXPECT_TRUE(fs::is_directory(root_ / first)) << row.pattern;
  }
}

// The checker catches a back edge, a node including another node or the
// registry, and LCM's generated types or Qt outside their places.
TEST_F(Layering, CheckerCatchesBackEdges) {
  // Generated headers are not in the source tree; everything else here is.
  const auto project = [](const std::string& header) { return header.rfind("nadir/", 0) != 0; };
  const std::vector<Include> bad = {
      {"core/bus.cpp", "gui/plots.h", false, 1},
      {"nodes/ppa/ppa_node.cpp", "nodes/vo_feature/features.h", false, 2},
      {"nodes/ppa/ppa_node.cpp", "nodes/registry.h", false, 3},
      {"logs/run_log.cpp", "logs/eval/metrics.h", false, 4},
      {"nodes/ppa/ppa_node.cpp", "nadir/pose_t.hpp", false, 5},
      {"logs/eval/metrics.cpp", "QString", true, 6},
  };
  EXPECT_EQ(violations(rules_, bad, project).size(), bad.size());
  const std::vector<Include> good = {
      {"gui/plots.cpp", "logs/eval/run_metrics.h", false, 1},
      {"nodes/ppa/ppa_node.cpp", "nodes/ppa/ppa_host.h", false, 2},
      {"nodes/ppa/ppa_entry.cpp", "nodes/registry.h", false, 3},
      {"terrain/procedural/fields.cpp", "terrain/world.h", false, 4},
      {"lcmtypes/codec.cpp", "nadir/pose_t.hpp", false, 5},
      {"gui/plots.cpp", "QString", true, 6},
  };
  EXPECT_TRUE(violations(rules_, good, project).empty());
}

// The project's own code keeps to the tables.
TEST_F(Layering, EveryIncludeKeepsToTheTables) {
  const std::vector<Include> includes = projectIncludes(root_);
  ASSERT_GT(includes.size(), 500u);
  const auto is_project = [this](const std::string& header) {
    return fs::exists(root_ / header);
  };
  std::string report;
  for (const std::string& v : violations(rules_, includes, is_project)) report += v + "\n";
  EXPECT_TRUE(report.empty()) << report;
}

}  // namespace
}  // namespace nadir::architecture
