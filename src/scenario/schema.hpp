// The scenario file's schema as data: every section's keys with their type, unit, accepted
// range, default and meaning. The loader takes its allowed keys and ranges from these tables,
// and `depotwin describe` prints them, so the documentation cannot drift from what is
// validated. No yaml-cpp here.
#pragma once

#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace depotwin {

// an inclusive or exclusive numeric range, for "must be > 0" style messages and the tables
struct ValueRange {
  double min = -std::numeric_limits<double>::infinity();
  bool min_inclusive = true;
  double max = std::numeric_limits<double>::infinity();
  bool max_inclusive = true;

  static ValueRange positive() { return {0.0, false}; }
  static ValueRange non_negative() { return {0.0, true}; }
  static ValueRange closed(double lo, double hi) { return {lo, true, hi, true}; }
  bool contains(double value) const;
  std::string text() const;  // e.g. "> 0", "in (0, 0.01]", "any" when unbounded
  bool bounded() const;      // some end is finite
};

// shortest text that prints a number the way a user wrote it (3, 0.25, 1e-05)
std::string format_number(double value);

// One key of a section.
struct SchemaKey {
  std::string name;
  std::string type;  // number, whole number, word, true | false, point, list, map, text
  std::string unit;  // mm, mm/s, s, deg, ...; "" for none
  ValueRange range;  // numbers: the values accepted
  std::vector<std::string> choices;     // words: the words accepted
  std::string default_text;             // as a user reads it: "0.1", "as_given", "required"
  std::optional<double> default_value;  // numbers: the default itself
  std::string meaning;                  // one line
  std::string applies_to;               // "" always; else e.g. "aerosol" or "extrusion"

  // what is accepted, for the tables: a range, the choices, or the type
  std::string accepted() const;
};

// One map of the scenario file (`process`, `toolpath.surface`, ...).
struct SchemaSection {
  std::string path;     // the dotted key of the map; "" for the top level
  std::string summary;  // one line
  std::vector<SchemaKey> keys;

  std::vector<std::string> key_names() const;
  // the key of this name; throws std::out_of_range for a name the table does not hold
  const SchemaKey& key(const std::string& name) const;
};

// every section of the scenario file, in the order of SCHEMA.md
const std::vector<SchemaSection>& scenario_schema();

// A section's table as SCHEMA.md holds it (a Markdown table: key, [applies to,] unit,
// accepted, default, meaning), so the document's tables are these tables' printout: a test
// compares them (SchemaDocument.TablesAreTheSchemasOwn).
std::string schema_markdown_table(const SchemaSection& section);
// the section at this dotted path; throws std::out_of_range for an unknown one
const SchemaSection& schema_section(const std::string& path);

// the defaults of `limits:` when the file gives none (the paper's stage, Thompson & Yoon)
constexpr double kDefaultTcpVMax_mm_s = 4.0;
constexpr double kDefaultTcpAMax_mm_s2 = 30.0;

// The joint angle, as printed and documented everywhere: the interior angle between
// consecutive segments at a joint (where they touch), 180 deg = straight on, 0 deg = a full
// reversal.
extern const char* const kJointAngleDefinition;

}  // namespace depotwin
