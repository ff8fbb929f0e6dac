// The lookup shared by the registries of problem builders by name (tracking's
// ProblemBuilderRegistry in backend/tracking/problem_builder.h, the windowed BA's
// WindowedBAProblemBuilderRegistry in backend/windowed_ba/windowed_ba_problem_builder.h): each
// family keeps its own Build signature and options type in a std::map<name, factory> built on
// each call (no global state); this finds a name or throws listing the known ones.
#ifndef PLDVO_BACKEND_OPTIMIZATION_PROBLEM_BUILDER_REGISTRY_H_
#define PLDVO_BACKEND_OPTIMIZATION_PROBLEM_BUILDER_REGISTRY_H_

#include <map>
#include <stdexcept>
#include <string>

namespace pldvo {

// The factory registered under `name`; throws std::invalid_argument
// "unknown <kind> '<name>'; known: a b c" otherwise.
template <class Factory>
const Factory& FindInRegistry(const std::map<std::string, Factory>& registry,
                              const std::string& name, const std::string& kind) {
  const auto it = registry.find(name);
  if (it == registry.end()) {
    std::string known;
    for (const auto& entry : registry) known += " " + entry.first;
    throw std::invalid_argument(std::string(__FILE__) + ": unknown " + kind + " '" + name +
                                "'; known:" + known);
  }
  return it->second;
}

// The names of a registry, space-separated (for option docs and messages).
template <class Factory>
std::string RegistryNames(const std::map<std::string, Factory>& registry) {
  std::string names;
  for (const auto& entry : registry) names += (names.empty() ? "" : " ") + entry.first;
  return names;
}

}  // namespace pldvo

#endif  // PLDVO_BACKEND_OPTIMIZATION_PROBLEM_BUILDER_REGISTRY_H_
