#pragma once
// Parameters: one struct per module, every field defaulted and documented,
// loaded from YAML. A struct lists its fields once, in a visit() member:
//
//   struct CameraParams {
//     double fps = 30.0;  // frame rate, Hz
//     void visit(ParamVisitor& v) {
//       v.field("fps", &fps, {.doc = "frame rate, Hz", .min = 0.1, .max = 2000});
//     }
//   };
//
// and everything else (loading, --set overrides, validation, printing) walks
// that list. An unknown key, a wrong type or an out-of-range value is a
// ParamError naming the file, line and key.

#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace nadir::core {

class ParamError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ParamSpec {
  std::string_view doc;
  // Inclusive bounds for numbers and for every element of a list.
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  // Allowed values of a string field; empty allows any.
  std::vector<std::string_view> choices = {};
  // Required length of a list field; 0 allows any.
  std::size_t list_size = 0;
  // A list of rows (a table): the allowed lengths of each row; empty allows any.
  std::vector<std::size_t> row_sizes = {};
};

// A table of numbers, YAML `[[1, 2], [3, 4, 5]]`: waypoints and the like.
using NumberRows = std::vector<std::vector<double>>;

using ParamRef = std::variant<bool*, int*, std::int64_t*, double*, std::string*,
                              std::vector<double>*, NumberRows*>;

// Access to a map of named entries of one params struct (see visitGroupMap).
struct GroupMapAccess {
  std::function<std::vector<std::string>()> names;
  // Adds a default entry under name (no-op if present).
  std::function<void(const std::string& name)> add;
  std::function<void(const std::string& name)> remove;
  std::function<void(const std::string& name, class ParamVisitor&)> visit;
};

class ParamVisitor {
 public:
  virtual ~ParamVisitor() = default;
  virtual void field(std::string_view key, ParamRef value, const ParamSpec& spec) = 0;
  // A nested struct under key; visit_members lists its fields.
  virtual void group(std::string_view key, std::string_view doc,
                     const std::function<void(ParamVisitor&)>& visit_members) = 0;
  // A map of named structs under key: YAML `key: {name: {...}, other: {...}}`.
  virtual void groupMap(std::string_view key, std::string_view doc,
                        const GroupMapAccess& access) = 0;
};

using VisitParams = std::function<void(ParamVisitor&)>;

// Nests a params struct P (with a visit member) under key.
template <class P>
void visitGroup(ParamVisitor& visitor, std::string_view key, std::string_view doc, P& params) {
  visitor.group(key, doc, [&params](ParamVisitor& inner) { params.visit(inner); });
}

// Nests a map of named params structs P under key; entries named in YAML are
// added with P's defaults, then their fields applied.
template <class P>
void visitGroupMap(ParamVisitor& visitor, std::string_view key, std::string_view doc,
                   std::map<std::string, P>& entries) {
  GroupMapAccess access;
  access.names = [&entries] {
    std::vector<std::string> names;
    for (const auto& entry : entries) names.push_back(entry.first);
    return names;
  };
  access.add = [&entries](const std::string& name) { entries.try_emplace(name); };
  access.remove = [&entries](const std::string& name) { entries.erase(name); };
  access.visit = [&entries](const std::string& name, ParamVisitor& inner) {
    entries.at(name).visit(inner);
  };
  visitor.groupMap(key, doc, access);
}

// Applies a YAML map to the fields. source names the file in errors.
void applyYamlFile(const std::string& path, const VisitParams& visit);
// Applies only the top-level keys named (others in the file are left alone): the
// part of a larger file that a program needs, such as a scenario's world.
void applyYamlFileKeys(const std::string& path, const std::vector<std::string>& keys,
                       const VisitParams& visit);
void applyYamlText(std::string_view yaml, std::string_view source, const VisitParams& visit);
// Applies "dotted.key=value" (value in YAML syntax: 3, true, [1, 2], text).
void applyAssignment(std::string_view assignment, std::string_view source,
                     const VisitParams& visit);
// The dotted keys ("world.origin_lat_deg") that a YAML file and then
// "key=value" assignments set, maps walked down to their leaves: what a user
// gave, as opposed to the defaults.
std::vector<std::string> givenKeys(const std::string& path,
                                   const std::vector<std::string>& assignments);
// Checks every current value against its spec (for values set in code).
void validateParams(const VisitParams& visit, std::string_view source);
// YAML text of every field with its value and documentation.
std::string formatParams(const VisitParams& visit);

template <class P>
P loadParams(const std::string& path) {
  P params;
  applyYamlFile(path, [&params](ParamVisitor& v) { params.visit(v); });
  return params;
}

template <class P>
void applyAssignments(P& params, const std::vector<std::string>& assignments,
                      std::string_view source = "--set") {
  for (const std::string& assignment : assignments) {
    applyAssignment(assignment, source, [&params](ParamVisitor& v) { params.visit(v); });
  }
}

template <class P>
std::string formatParamsOf(P& params) {
  return formatParams([&params](ParamVisitor& v) { params.visit(v); });
}

// A params struct of any type (one with visit()), held by value: what the node
// registry passes around for each node without knowing its type.
class AnyParams {
 public:
  template <class P>
  explicit AnyParams(P params) : self_(std::make_unique<Model<P>>(std::move(params))) {}
  AnyParams(const AnyParams& other) : self_(other.self_->clone()) {}
  AnyParams& operator=(const AnyParams& other) {
    if (this != &other) self_ = other.self_->clone();
    return *this;
  }
  AnyParams(AnyParams&&) noexcept = default;
  AnyParams& operator=(AnyParams&&) noexcept = default;

  void visit(ParamVisitor& v) { self_->visit(v); }
  // The struct as its type; throws std::logic_error for another type.
  template <class P>
  P& as() {
    auto* model = dynamic_cast<Model<P>*>(self_.get());
    if (model == nullptr) throw std::logic_error("AnyParams: not the type asked for");
    return model->value;
  }
  template <class P>
  const P& as() const {
    return const_cast<AnyParams*>(this)->as<P>();
  }

 private:
  struct Concept {
    virtual ~Concept() = default;
    virtual std::unique_ptr<Concept> clone() const = 0;
    virtual void visit(ParamVisitor& v) = 0;
  };
  template <class P>
  struct Model final : Concept {
    explicit Model(P p) : value(std::move(p)) {}
    std::unique_ptr<Concept> clone() const override { return std::make_unique<Model>(value); }
    void visit(ParamVisitor& v) override { value.visit(v); }
    P value;
  };
  std::unique_ptr<Concept> self_;
};

}  // namespace nadir::core
