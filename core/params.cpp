#include "core/params.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>

namespace nadir::core {
namespace {

template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
// Clang before 17 does not deduce an aggregate's template arguments by itself.
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

std::string joinKey(const std::string& prefix, std::string_view key) {
  return prefix.empty() ? std::string(key) : prefix + "." + std::string(key);
}

// Shortest text that reads back as the same double.
std::string formatNumber(double value) {
  char text[64];
  const auto result = std::to_chars(text, text + sizeof(text), value);
  return std::string(text, result.ptr);
}

std::string formatList(const std::vector<double>& values) {
  std::string list = "[";
  for (std::size_t i = 0; i < values.size(); ++i) list += (i ? ", " : "") + formatNumber(values[i]);
  return list + "]";
}

std::string describeRange(const ParamSpec& spec) {
  return "[" + formatNumber(spec.min) + ", " + formatNumber(spec.max) + "]";
}

// Errors read "<where>: <key>: <problem>", where is "file:line" when known.
[[noreturn]] void fail(const std::string& where, const std::string& key,
                       const std::string& problem) {
  throw ParamError(where + ": " + key + ": " + problem);
}

void checkNumber(double value, const ParamSpec& spec, const std::string& where,
                 const std::string& key) {
  if (!std::isfinite(value)) fail(where, key, "value must be a finite number");
  if (value < spec.min || value > spec.max) {
    fail(where, key, formatNumber(value) + " is out of range " + describeRange(spec));
  }
}

void checkValue(const ParamRef& ref, const ParamSpec& spec, const std::string& where,
                const std::string& key) {
  std::visit(
      Overloaded{
          [](bool*) {},
          [&](int* value) { checkNumber(*value, spec, where, key); },
          [&](std::int64_t* value) { checkNumber(static_cast<double>(*value), spec, where, key); },
          [&](double* value) { checkNumber(*value, spec, where, key); },
          [&](std::string* value) {
            if (spec.choices.empty() ||
                std::find(spec.choices.begin(), spec.choices.end(), *value) != spec.choices.end()) {
              return;
            }
            std::string allowed;
            for (std::string_view choice : spec.choices) {
              allowed += (allowed.empty() ? "" : ", ") + std::string(choice);
            }
            fail(where, key, "'" + *value + "' is not one of: " + allowed);
          },
          [&](std::vector<double>* values) {
            if (spec.list_size != 0 && values->size() != spec.list_size) {
              fail(where, key,
                   "expected a list of " + std::to_string(spec.list_size) + " numbers, got " +
                       std::to_string(values->size()));
            }
            for (double value : *values) checkNumber(value, spec, where, key);
          },
          [&](NumberRows* rows) {
            if (spec.list_size != 0 && rows->size() != spec.list_size) {
              fail(where, key,
                   "expected " + std::to_string(spec.list_size) + " rows, got " +
                       std::to_string(rows->size()));
            }
            for (std::size_t i = 0; i < rows->size(); ++i) {
              const std::vector<double>& row = (*rows)[i];
              const std::string row_key = key + "[" + std::to_string(i) + "]";
              if (!spec.row_sizes.empty() && std::find(spec.row_sizes.begin(), spec.row_sizes.end(),
                                                       row.size()) == spec.row_sizes.end()) {
                std::string allowed;
                for (std::size_t size : spec.row_sizes) {
                  allowed += (allowed.empty() ? "" : " or ") + std::to_string(size);
                }
                fail(where, row_key,
                     "expected " + allowed + " numbers, got " + std::to_string(row.size()));
              }
              for (double value : row) checkNumber(value, spec, where, row_key);
            }
          },
      },
      ref);
}

const char* typeName(const ParamRef& ref) {
  return std::visit(Overloaded{
                        [](bool*) { return "true or false"; },
                        [](int*) { return "an integer"; },
                        [](std::int64_t*) { return "an integer"; },
                        [](double*) { return "a number"; },
                        [](std::string*) { return "a string"; },
                        [](std::vector<double>*) { return "a list of numbers"; },
                        [](NumberRows*) { return "a list of lists of numbers"; },
                    },
                    ref);
}

// Converts node into the field's type; yaml-cpp throws on a mismatch.
void convertInto(const YAML::Node& node, const ParamRef& ref) {
  std::visit(Overloaded{
                 [&](bool* value) { *value = node.as<bool>(); },
                 [&](int* value) { *value = node.as<int>(); },
                 [&](std::int64_t* value) { *value = node.as<std::int64_t>(); },
                 [&](double* value) { *value = node.as<double>(); },
                 [&](std::string* value) {
                   if (!node.IsScalar()) throw YAML::BadConversion(node.Mark());
                   *value = node.as<std::string>();
                 },
                 [&](std::vector<double>* value) { *value = node.as<std::vector<double>>(); },
                 [&](NumberRows* value) { *value = node.as<NumberRows>(); },
             },
             ref);
}

class YamlApplier final : public ParamVisitor {
 public:
  // A dry run checks everything and assigns nothing, so that a document with
  // one bad entry changes no field at all.
  YamlApplier(const YAML::Node& map, std::string source, std::string prefix, bool with_lines,
              bool dry_run)
      : map_(map),
        source_(std::move(source)),
        prefix_(std::move(prefix)),
        with_lines_(with_lines),
        dry_run_(dry_run) {}

  void field(std::string_view key, ParamRef value, const ParamSpec& spec) override {
    known_.emplace_back(key);
    const YAML::Node node = map_[std::string(key)];
    if (!node) return;
    const std::string full_key = joinKey(prefix_, key);
    // An empty value's mark points past the key, so name the key's line.
    const std::string where = whereIs(node.IsNull() ? keyNode(key) : node);
    if (node.IsNull()) {
      fail(where, full_key, "has no value (expected " + std::string(typeName(value)) + ")");
    }
    std::visit(
        [&](auto* field) {
          auto parsed = *field;
          try {
            convertInto(node, ParamRef(&parsed));
          } catch (const YAML::Exception&) {
            fail(where, full_key,
                 "expected " + std::string(typeName(value)) + ", got '" + YAML::Dump(node) + "'");
          }
          checkValue(ParamRef(&parsed), spec, where, full_key);
          if (!dry_run_) *field = std::move(parsed);
        },
        value);
  }

  void group(std::string_view key, std::string_view /*doc*/,
             const std::function<void(ParamVisitor&)>& visit_members) override {
    known_.emplace_back(key);
    const YAML::Node node = map_[std::string(key)];
    if (!node) return;
    const std::string full_key = joinKey(prefix_, key);
    if (!node.IsMap()) fail(whereIs(node), full_key, "expected a map of its fields");
    YamlApplier inner(node, source_, full_key, with_lines_, dry_run_);
    visit_members(inner);
    inner.rejectUnknownKeys();
  }

  void groupMap(std::string_view key, std::string_view /*doc*/,
                const GroupMapAccess& access) override {
    known_.emplace_back(key);
    const YAML::Node node = map_[std::string(key)];
    if (!node) return;
    const std::string full_key = joinKey(prefix_, key);
    if (!node.IsMap()) fail(whereIs(node), full_key, "expected a map of named entries");
    const std::vector<std::string> existing = access.names();
    std::vector<std::string> seen;
    for (const auto& entry : node) {
      const std::string name = keyText(entry.first, full_key);
      const std::string entry_key = joinKey(full_key, name);
      if (std::find(seen.begin(), seen.end(), name) != seen.end()) {
        fail(whereIs(entry.first), entry_key, "given twice");
      }
      seen.push_back(name);
      if (!entry.second.IsMap())
        fail(whereIs(entry.second), entry_key, "expected a map of its fields");
      const bool is_new = std::find(existing.begin(), existing.end(), name) == existing.end();
      access.add(name);
      YamlApplier inner(entry.second, source_, entry_key, with_lines_, dry_run_);
      try {
        access.visit(name, inner);
        inner.rejectUnknownKeys();
      } catch (...) {
        if (is_new) access.remove(name);
        throw;
      }
      // A dry run leaves no trace, not even the entries it had to create.
      if (dry_run_ && is_new) access.remove(name);
    }
  }

  void rejectUnknownKeys() const {
    std::vector<std::string> seen;
    for (const auto& entry : map_) {
      const std::string key = keyText(entry.first, prefix_);
      if (std::find(seen.begin(), seen.end(), key) != seen.end()) {
        fail(whereIs(entry.first), joinKey(prefix_, key), "given twice");
      }
      seen.push_back(key);
      if (std::find(known_.begin(), known_.end(), key) != known_.end()) continue;
      std::string known;
      for (const std::string& name : known_) known += (known.empty() ? "" : ", ") + name;
      fail(whereIs(entry.first), joinKey(prefix_, key),
           "unknown key (known here: " + (known.empty() ? std::string("none") : known) + ")");
    }
  }

 private:
  // A map key as text; a key that is a list or a map (YAML's "? [a, b]") is an error.
  std::string keyText(const YAML::Node& key, const std::string& within) const {
    if (!key.IsScalar()) {
      const std::string problem = "a key must be a name, not a list or a map";
      if (within.empty()) throw ParamError(whereIs(key) + ": " + problem);
      fail(whereIs(key), within, problem);
    }
    return key.Scalar();
  }

  std::string whereIs(const YAML::Node& node) const {
    if (!with_lines_ || node.Mark().is_null()) return source_;
    return source_ + ":" + std::to_string(node.Mark().line + 1);
  }

  YAML::Node keyNode(std::string_view key) const {
    for (const auto& entry : map_) {
      if (entry.first.Scalar() == key) return entry.first;
    }
    return map_;
  }

  const YAML::Node map_;
  std::string source_;
  std::string prefix_;
  bool with_lines_;
  bool dry_run_;
  std::vector<std::string> known_;
};

void applyRoot(const YAML::Node& root, const std::string& source, bool with_lines,
               const VisitParams& visit) {
  if (!root || root.IsNull()) return;  // an empty file sets nothing
  if (!root.IsMap()) throw ParamError(source + ": expected a map of parameters at the top level");
  for (const bool dry_run : {true, false}) {
    YamlApplier applier(root, source, "", with_lines, dry_run);
    visit(applier);
    applier.rejectUnknownKeys();
  }
}

class Validator final : public ParamVisitor {
 public:
  Validator(std::string source, std::string prefix)
      : source_(std::move(source)), prefix_(std::move(prefix)) {}
  void field(std::string_view key, ParamRef value, const ParamSpec& spec) override {
    checkValue(value, spec, source_, joinKey(prefix_, key));
  }
  void group(std::string_view key, std::string_view /*doc*/,
             const std::function<void(ParamVisitor&)>& visit_members) override {
    Validator inner(source_, joinKey(prefix_, key));
    visit_members(inner);
  }
  void groupMap(std::string_view key, std::string_view /*doc*/,
                const GroupMapAccess& access) override {
    for (const std::string& name : access.names()) {
      Validator inner(source_, joinKey(joinKey(prefix_, key), name));
      access.visit(name, inner);
    }
  }

 private:
  std::string source_;
  std::string prefix_;
};

class Formatter final : public ParamVisitor {
 public:
  Formatter(std::ostringstream& out, int indent) : out_(out), indent_(indent) {}
  void field(std::string_view key, ParamRef value, const ParamSpec& spec) override {
    out_ << std::string(static_cast<std::size_t>(indent_), ' ') << key << ": " << text(value);
    if (!spec.doc.empty()) out_ << "  # " << spec.doc;
    out_ << "\n";
  }
  void group(std::string_view key, std::string_view doc,
             const std::function<void(ParamVisitor&)>& visit_members) override {
    out_ << std::string(static_cast<std::size_t>(indent_), ' ') << key << ":";
    if (!doc.empty()) out_ << "  # " << doc;
    out_ << "\n";
    Formatter inner(out_, indent_ + 2);
    visit_members(inner);
  }
  void groupMap(std::string_view key, std::string_view doc, const GroupMapAccess& access) override {
    const std::vector<std::string> names = access.names();
    // An empty map is written {} before the comment, so that it reads back as a map.
    out_ << std::string(static_cast<std::size_t>(indent_), ' ') << key << ":"
         << (names.empty() ? " {}" : "");
    if (!doc.empty()) out_ << "  # " << doc;
    out_ << "\n";
    for (const std::string& name : names) {
      out_ << std::string(static_cast<std::size_t>(indent_ + 2), ' ') << name << ":\n";
      Formatter inner(out_, indent_ + 4);
      access.visit(name, inner);
    }
  }

 private:
  static std::string text(const ParamRef& ref) {
    return std::visit(Overloaded{
                          [](bool* value) { return std::string(*value ? "true" : "false"); },
                          [](int* value) { return std::to_string(*value); },
                          [](std::int64_t* value) { return std::to_string(*value); },
                          [](double* value) { return formatNumber(*value); },
                          [](std::string* value) {
                            YAML::Emitter emitter;
                            emitter << YAML::DoubleQuoted << *value;
                            return std::string(emitter.c_str());
                          },
                          [](std::vector<double>* values) { return formatList(*values); },
                          [](NumberRows* rows) {
                            std::string table = "[";
                            for (std::size_t i = 0; i < rows->size(); ++i) {
                              table += (i ? ", " : "") + formatList((*rows)[i]);
                            }
                            return table + "]";
                          },
                      },
                      ref);
  }

  std::ostringstream& out_;
  int indent_;
};

YAML::Node loadYamlFile(const std::string& path) {
  try {
    return YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw ParamError(path + ": cannot open parameter file");
  } catch (const YAML::ParserException& e) {
    throw ParamError(path + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML: " + e.msg);
  }
}

void collectLeafKeys(const YAML::Node& node, const std::string& prefix,
                     std::vector<std::string>& keys) {
  if (!node.IsMap()) {
    if (!prefix.empty()) keys.push_back(prefix);
    return;
  }
  for (const auto& entry : node) {
    collectLeafKeys(entry.second, joinKey(prefix, entry.first.Scalar()), keys);
  }
}

}  // namespace

std::vector<std::string> givenKeys(const std::string& path,
                                   const std::vector<std::string>& assignments) {
  std::vector<std::string> keys;
  const YAML::Node root = loadYamlFile(path);
  if (root && root.IsMap()) collectLeafKeys(root, "", keys);
  for (const std::string& assignment : assignments) {
    const auto eq = assignment.find('=');
    if (eq == std::string::npos || eq == 0) continue;
    YAML::Node value;
    try {
      value = YAML::Load(assignment.substr(eq + 1));
    } catch (const YAML::ParserException&) {
      continue;  // applyAssignment reports it
    }
    collectLeafKeys(value, assignment.substr(0, eq), keys);
  }
  return keys;
}

void applyYamlFile(const std::string& path, const VisitParams& visit) {
  applyRoot(loadYamlFile(path), path, true, visit);
}

void applyYamlFileKeys(const std::string& path, const std::vector<std::string>& keys,
                       const VisitParams& visit) {
  const YAML::Node root = loadYamlFile(path);
  if (!root || root.IsNull()) return;
  if (!root.IsMap()) throw ParamError(path + ": expected a map of parameters at the top level");
  YAML::Node part(YAML::NodeType::Map);
  for (const std::string& key : keys) {
    if (root[key]) part[key] = root[key];
  }
  applyRoot(part, path, true, visit);
}

void applyYamlText(std::string_view yaml, std::string_view source, const VisitParams& visit) {
  YAML::Node root;
  try {
    root = YAML::Load(std::string(yaml));
  } catch (const YAML::ParserException& e) {
    throw ParamError(std::string(source) + ":" + std::to_string(e.mark.line + 1) +
                     ": not valid YAML: " + e.msg);
  }
  applyRoot(root, std::string(source), true, visit);
}

void applyAssignment(std::string_view assignment, std::string_view source,
                     const VisitParams& visit) {
  const std::string where = std::string(source) + " " + std::string(assignment);
  const auto eq = assignment.find('=');
  if (eq == std::string_view::npos || eq == 0) {
    throw ParamError(where + ": expected key=value");
  }
  const std::string key(assignment.substr(0, eq));
  YAML::Node value;
  try {
    value = YAML::Load(std::string(assignment.substr(eq + 1)));
  } catch (const YAML::ParserException& e) {
    throw ParamError(where + ": the value is not valid YAML: " + e.msg);
  }
  // Nest the value under the dotted key path: a.b=1 -> {a: {b: 1}}.
  YAML::Node root(YAML::NodeType::Map);
  YAML::Node cursor = root;
  std::size_t start = 0;
  while (true) {
    const auto dot = key.find('.', start);
    const std::string part =
        key.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
    if (part.empty()) throw ParamError(where + ": empty part in key '" + key + "'");
    if (dot == std::string::npos) {
      cursor[part] = value;
      break;
    }
    cursor[part] = YAML::Node(YAML::NodeType::Map);
    cursor.reset(cursor[part]);
    start = dot + 1;
  }
  applyRoot(root, where, false, visit);
}

void validateParams(const VisitParams& visit, std::string_view source) {
  Validator validator{std::string(source), ""};
  visit(validator);
}

std::string formatParams(const VisitParams& visit) {
  std::ostringstream out;
  Formatter formatter(out, 0);
  visit(formatter);
  return out.str();
}

}  // namespace nadir::core
