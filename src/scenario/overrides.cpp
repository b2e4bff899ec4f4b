// Scenario overrides: the YAML tree of a scenario edited before it is loaded
// (scenario/overrides.hpp).
#include "scenario/overrides.hpp"

#include <yaml-cpp/depthguard.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>

#include "core/number_text.hpp"
#include "scenario/override_tree.hpp"
#include "scenario/scenario.hpp"

namespace depotwin {

namespace scenario_detail {

std::optional<YAML::Node> parse_scenario_text(const std::string& text, ProblemList& problems,
                                              const std::string& kind,
                                              std::vector<int>* aliased_positions) {
  // text only: a NUL, a control byte or bytes that are not UTF-8 (a Latin-1 name) would reach
  // names, folders and JSON otherwise, or be misread by the YAML parser
  if (const std::size_t at = first_non_text_byte(text); at != std::string::npos) {
    const std::size_t newline = at == 0 ? std::string::npos : text.rfind('\n', at - 1);
    const std::size_t column = newline == std::string::npos ? at + 1 : at - newline;
    const auto byte = static_cast<unsigned char>(text[at]);
    char shown[8];
    std::snprintf(shown, sizeof shown, "0x%02X", byte);
    const bool control = byte < 0x20 || byte == 0x7F;
    problems.add(
        static_cast<int>(std::count(text.begin(), text.begin() + at, '\n')) + 1, "",
        std::string(control ? "control byte " : "byte ") + shown + (byte == 0 ? " (NUL)" : "") +
            " at column " + std::to_string(column) +
            (control ? ": a " + kind + " is text (YAML)"
                     : " is not UTF-8: a " + kind + " is UTF-8 text (YAML); save it as UTF-8"));
    return std::nullopt;
  }
  // exactly one YAML document (load_documents: not YAML::LoadAll, which never returns on some
  // malformed text)
  YamlDocuments documents;
  try {
    documents = load_documents(text);
  } catch (const YAML::DeepRecursion& e) {
    // yaml-cpp stops a parse hundreds of levels deep with the words "bad file"
    problems.add(e.mark.is_null() ? 0 : e.mark.line + 1, "",
                 "malformed YAML: lists or maps nested hundreds of levels deep (a " + kind +
                     " nests a few)");
    return std::nullopt;
  } catch (const YAML::ParserException& e) {
    const int line = e.mark.is_null() ? 0 : e.mark.line + 1;
    // the two slips the parser's words do not name: a tab in the indentation, CR line ends
    std::string hint;
    int line_number = 1;
    for (std::size_t at = 0; at < text.size() && hint.empty() && (line == 0 || line_number <= line);
         at = text.find('\n', at), at = at == std::string::npos ? text.size() : at + 1) {
      std::size_t k = at;
      while (k < text.size() && (text[k] == ' ' || text[k] == '\t')) {
        if (text[k] == '\t')
          hint = " (line " + std::to_string(line_number) +
                 " is indented with a tab: YAML indents with spaces only)";
        ++k;
      }
      ++line_number;
    }
    if (hint.empty() && text.find('\r') != std::string::npos &&
        text.find('\n') == std::string::npos)
      hint = " (the file's lines end in CR alone, as old Mac files: save it with LF line ends)";
    problems.add(line, "", "malformed YAML: " + e.msg + hint);
    return std::nullopt;
  } catch (const YAML::Exception& e) {
    problems.add(0, "", std::string("malformed YAML: ") + e.what());
    return std::nullopt;
  }
  if (documents.count == 0 || documents.first.IsNull()) {
    problems.add(1, "",
                 kind == "sweep"
                     ? "the file holds nothing: expected a map with base: and grid:"
                     : "the file holds no settings: expected a map with at least `toolpath:`");
    return std::nullopt;
  }
  if (documents.count > 1) {
    problems.add(documents.second_line, "",
                 "more than one YAML document (---): a " + kind + " file holds one");
    return std::nullopt;
  }
  // a tag would make text of a number (`!!str 3`) or null of a value (`!!null 3`), which the
  // reader, going by the scalar's text, would not see: refused rather than read differently
  if (documents.first_tag_line > 0) {
    problems.add(documents.first_tag_line, "",
                 "YAML tag '" + printable_text(documents.first_tag) + "': a " + kind +
                     " file's values are plain (3 is a number, \"3\" text); write it without "
                     "the tag");
    return std::nullopt;
  }
  if (aliased_positions != nullptr) *aliased_positions = std::move(documents.aliased_positions);
  return documents.first;
}

std::optional<std::vector<KeyStep>> parse_override_key(const std::string& key, std::string& why) {
  std::vector<KeyStep> steps;
  const auto is_name_char = [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_';
  };
  std::size_t at = 0;
  if (key.empty()) {
    why = "an empty key";
    return std::nullopt;
  }
  while (at < key.size()) {
    // a name ...
    const std::size_t begin = at;
    while (at < key.size() && is_name_char(key[at])) ++at;
    if (at == begin) {
      why = "expected a key name at character " + std::to_string(begin + 1) +
            " (keys are names joined by dots, with [index] for list entries: planners[0].delta)";
      return std::nullopt;
    }
    steps.push_back(KeyStep{key.substr(begin, at - begin), -1});
    // ... with list indices after it ...
    while (at < key.size() && key[at] == '[') {
      const std::size_t digits = at + 1;
      std::size_t close = digits;
      while (close < key.size() && std::isdigit(static_cast<unsigned char>(key[close]))) ++close;
      if (close == digits || close >= key.size() || key[close] != ']' || close - digits > 9) {
        why = "a list index is [N] with N a whole number from 0 (character " +
              std::to_string(at + 1) + ")";
        return std::nullopt;
      }
      steps.push_back(KeyStep{"", std::stoll(key.substr(digits, close - digits))});
      at = close + 1;
    }
    // ... then a dot and the next name, or the end
    if (at == key.size()) break;
    if (key[at] != '.' || at + 1 == key.size()) {
      why = "unexpected '" + std::string(1, key[at]) + "' at character " + std::to_string(at + 1) +
            " (keys are names joined by dots, with [index] for list entries: planners[0].delta)";
      return std::nullopt;
    }
    ++at;
  }
  return steps;
}

std::string flow_text(const YAML::Node& node) {
  if (node.IsScalar()) return node.Scalar();
  YAML::Emitter out;
  out.SetMapFormat(YAML::Flow);
  out.SetSeqFormat(YAML::Flow);
  out << node;
  return out.c_str();
}

namespace {

// the dotted text of the first `count` steps (`planners[0]`)
std::string key_text(const std::vector<KeyStep>& steps, std::size_t count) {
  std::string text;
  for (std::size_t i = 0; i < count; ++i) {
    if (steps[i].name.empty())
      text += "[" + std::to_string(steps[i].index) + "]";
    else
      text += (text.empty() ? "" : ".") + steps[i].name;
  }
  return text;
}

// The key a scalar stands for where the schema also takes a map: a planner name
// (`planners[i]`: {name: X}), an order (`order`: {method: X}), a G-code file
// (`toolpath.gcode`: {file: X}); empty where there is none.
std::string map_form_key(const std::vector<KeyStep>& steps, std::size_t count) {
  if (count == 2 && steps[0].name == "planners" && steps[1].name.empty()) return "name";
  if (count == 1 && steps[0].name == "order") return "method";
  if (count == 2 && steps[0].name == "toolpath" && steps[1].name == "gcode") return "file";
  return "";
}

// what a node holds, for messages
std::string what_is(const YAML::Node& node) {
  if (node.IsSequence()) return "a list";
  if (node.IsMap()) return "a map";
  if (node.IsScalar()) return "'" + node.Scalar() + "'";
  return "nothing";
}

// Sets `steps` in `root` to `value`; "" or what went wrong.
std::string set_value(YAML::Node root, const std::vector<KeyStep>& steps, const YAML::Node& value,
                      const std::vector<int>& aliased_positions) {
  // a node an alias repeats is one node in the tree: editing it edits every place it is named
  const auto aliased = [&](const YAML::Node& node) {
    return node.IsDefined() && !node.Mark().is_null() &&
           std::find(aliased_positions.begin(), aliased_positions.end(), node.Mark().pos) !=
               aliased_positions.end();
  };
  const auto shared_problem = [&](const std::string& walked) {
    return walked +
           " is an anchored node (&) that an alias (*) repeats in the base scenario: "
           "an override there would change every place the alias names; write " +
           walked + " out in the base scenario";
  };
  YAML::Node current;
  current.reset(root);
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const KeyStep& step = steps[i];
    const bool last = i + 1 == steps.size();
    const std::string walked = key_text(steps, i);
    if (i > 0 && aliased(current)) return shared_problem(walked);
    if (!step.name.empty()) {
      // a map key: a scalar with a map form becomes that map, e.g. a planner name {name: X}
      if (current.IsScalar() && !map_form_key(steps, i).empty()) {
        YAML::Node as_map(YAML::NodeType::Map);
        as_map[map_form_key(steps, i)] = current.Scalar();
        current = as_map;  // replaces the node in the tree
      }
      if (!current.IsMap())
        return walked + " is " + what_is(current) + " in the base scenario, not a map: override " +
               walked + " as a whole";
      if (last) {
        // a value an alias repeats is unbound from this key first: assigned in place, it
        // would be replaced everywhere the alias names it
        if (aliased(current[step.name])) current.remove(step.name);
        // null (~) removes the key, e.g. toolpath.segments before toolpath.polylines is set
        if (value.IsNull())
          current.remove(step.name);
        else
          current[step.name] = value;
        return "";
      }
      YAML::Node child = current[step.name];
      if (!child.IsDefined() || child.IsNull()) {
        current[step.name] = YAML::Node(YAML::NodeType::Map);
        child.reset(current[step.name]);
      }
      current.reset(child);
    } else {
      // a list entry that exists
      if (!current.IsSequence())
        return walked + " is " + what_is(current) + " in the base scenario, not a list";
      if (step.index >= static_cast<long long>(current.size()))
        return walked + " has " + std::to_string(current.size()) +
               (current.size() == 1 ? " entry" : " entries") + " in the base scenario (" + walked +
               "[0]" +
               (current.size() > 1 ? ".." + walked + "[" + std::to_string(current.size() - 1) + "]"
                                   : "") +
               ")";
      if (last) {
        if (aliased(current[static_cast<std::size_t>(step.index)]))
          return shared_problem(key_text(steps, i + 1));
        if (value.IsNull())
          return walked + "[" + std::to_string(step.index) +
                 "]: a list entry cannot be removed (~); override the whole list";
        current[static_cast<std::size_t>(step.index)] = value;
        return "";
      }
      YAML::Node child = current[static_cast<std::size_t>(step.index)];
      current.reset(child);
    }
  }
  return "";
}

// a planner entry's run label and name (`lspb_mtt`, `{name: conformal, label: control_none}`)
void planner_names(const YAML::Node& entry, std::string& label, std::string& name) {
  label.clear();
  name.clear();
  if (entry.IsScalar()) {
    name = entry.Scalar();
  } else if (entry.IsMap()) {
    if (entry["name"] && entry["name"].IsScalar()) name = entry["name"].Scalar();
    if (entry["label"] && entry["label"].IsScalar()) label = entry["label"].Scalar();
  }
}

// `planner`: keeps one planner of the scenario (by run label, then by name), or names another
std::string select_planner(YAML::Node root, const YAML::Node& value) {
  const YAML::Node& const_root = root;
  const YAML::Node planners = const_root["planners"];
  YAML::Node chosen = value;
  if (value.IsScalar() && planners && planners.IsSequence()) {
    const std::string wanted = value.Scalar();
    std::vector<std::size_t> by_label, by_name;
    std::string label, name;
    for (std::size_t i = 0; i < planners.size(); ++i) {
      planner_names(planners[i], label, name);
      if (label == wanted) by_label.push_back(i);
      if (name == wanted) by_name.push_back(i);
    }
    const std::vector<std::size_t>& found = by_label.empty() ? by_name : by_label;
    if (found.size() > 1) {
      std::string labels;
      for (const std::size_t i : found) {
        planner_names(planners[i], label, name);
        labels += (labels.empty() ? "" : ", ") + (label.empty() ? name : label);
      }
      return "'" + wanted + "' matches " + std::to_string(found.size()) +
             " planners of the base scenario (" + labels + "): name one by its label";
    }
    if (found.size() == 1) chosen = YAML::Clone(planners[found.front()]);
  }
  YAML::Node list(YAML::NodeType::Sequence);
  list.push_back(chosen);
  root["planners"] = list;
  return "";
}

bool starts_with(const std::string& text, const std::string& prefix) {
  return text.compare(0, prefix.size(), prefix) == 0;
}

}  // namespace

void apply_overrides(YAML::Node root, const std::vector<ScenarioOverride>& overrides,
                     std::vector<Problem>& problems, const std::vector<int>& aliased_positions) {
  if (!root.IsMap()) return;  // the loader says what the file should be
  const auto apply = [&](const ScenarioOverride& override_) {
    const auto problem = [&](const std::string& message) {
      problems.push_back(Problem{override_.file, override_.line, override_.key, message});
    };
    YAML::Node value;
    try {
      value = YAML::Load(override_.value_yaml);
    } catch (const YAML::Exception& e) {
      problem(std::string("malformed value: ") + e.what());
      return;
    }
    if (override_.key == "planner") {
      const std::string why = select_planner(root, value);
      if (!why.empty()) problem(why);
      return;
    }
    std::string why;
    const std::optional<std::vector<KeyStep>> steps = parse_override_key(override_.key, why);
    if (!steps) {
      problem(why);
      return;
    }
    why = set_value(root, *steps, value, aliased_positions);
    if (!why.empty()) problem(why);
  };
  // every override in order, `planner` last (planners[i] names the base scenario's list)
  for (const ScenarioOverride& override_ : overrides)
    if (override_.key != "planner") apply(override_);
  for (const ScenarioOverride& override_ : overrides)
    if (override_.key == "planner") apply(override_);
}

void attribute_to_overrides(std::vector<Problem>& problems,
                            const std::vector<ScenarioOverride>& overrides) {
  for (Problem& problem : problems) {
    const ScenarioOverride* owner = nullptr;
    std::size_t owner_length = 0;
    for (const ScenarioOverride& override_ : overrides) {
      const std::string key = override_.key == "planner" ? "planners" : override_.key;
      // (or a key the override made on its way, unknown: `bogus.key` makes `bogus`)
      const bool makes_unknown =
          starts_with(problem.message, "unknown key") &&
          (starts_with(key, problem.key + ".") || starts_with(key, problem.key + "["));
      const bool under = problem.key == key || starts_with(problem.key, key + ".") ||
                         starts_with(problem.key, key + "[") || makes_unknown;
      // the most specific override wins (limits.x.v_max over limits)
      if (under && key.size() >= owner_length) {
        owner = &override_;
        owner_length = key.size();
      }
    }
    if (owner == nullptr) continue;
    problem.file = owner->file;
    problem.line = owner->line;
  }
}

}  // namespace scenario_detail

std::string override_key_problem(const std::string& key) {
  if (key == "planner") return "";
  std::string why;
  return scenario_detail::parse_override_key(key, why) ? "" : why;
}

ResolvedScenario resolve_scenario(const std::string& path, const std::string& text,
                                  const std::vector<ScenarioOverride>& overrides) {
  using namespace scenario_detail;
  ProblemList problems(path);
  std::vector<int> aliased_positions;
  std::optional<YAML::Node> root =
      parse_scenario_text(text, problems, "scenario", &aliased_positions);
  if (!root) throw InputError(problems.problems());
  apply_overrides(*root, overrides, problems.problems(), aliased_positions);
  if (!problems.empty()) throw InputError(problems.problems());

  ResolvedScenario resolved;
  YAML::Emitter out;
  out << *root;
  resolved.text = out.c_str();
  // the files it reads: an MJCF model, a G-code file, a part's STL
  const std::filesystem::path directory = std::filesystem::path(path).parent_path();
  const auto add_file = [&](const YAML::Node& node) {
    if (node && node.IsScalar())
      resolved.input_files.push_back((directory / node.Scalar()).lexically_normal().string());
  };
  const YAML::Node& tree = *root;
  if (tree.IsMap()) {
    if (tree["machine"] && tree["machine"].IsMap()) add_file(tree["machine"]["model"]);
    if (tree["machine"] && tree["machine"].IsScalar())
      resolved.shipped_machine = tree["machine"].Scalar();
    if (!tree["machine"]) resolved.shipped_machine = kDefaultMachine;  // none named
    const YAML::Node toolpath = tree["toolpath"];
    if (toolpath && toolpath.IsMap()) {
      const YAML::Node gcode = toolpath["gcode"];
      if (gcode && gcode.IsScalar()) add_file(gcode);
      if (gcode && gcode.IsMap()) add_file(gcode["file"]);
      if (toolpath["surface"] && toolpath["surface"].IsMap()) add_file(toolpath["surface"]["file"]);
    }
    // the planners it runs, by run label
    const YAML::Node planners = tree["planners"];
    if (planners && planners.IsSequence()) {
      resolved.planners.emplace();
      std::string label, name;
      for (std::size_t i = 0; i < planners.size(); ++i) {
        planner_names(planners[i], label, name);
        resolved.planners->push_back(label.empty() ? name : label);
      }
    }
  }
  return resolved;
}

}  // namespace depotwin
