// `depotwin describe [TOPIC] [--json]`: every parameter a scenario can set, with its unit,
// accepted range, default and meaning, printed from the tables the loader validates against
// (scenario/schema.hpp, the planner, sequencer and machine registries), so what is documented
// is what is checked.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

namespace depotwin {

// the topics, each with one line of what it covers, in the order `describe` lists them
const std::vector<std::pair<std::string, std::string>>& describe_topics();

// A topic as aligned tables (text) or as JSON; "" lists the topics. InputError (key
// `describe`) for an unknown topic, naming the known ones.
std::string describe_text(const std::string& topic);
nlohmann::json describe_json(const std::string& topic);

// the verb: prints the text or the JSON on stdout; returns the exit status
int describe_verb(const std::string& topic, bool json);

}  // namespace depotwin
