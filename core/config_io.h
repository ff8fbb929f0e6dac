// Visitors for the VisitFields pattern of core/options.h: load a YAML config, apply
// `--set key=value` overrides, write the effective config, and document the options, for any
// struct with a `template <class V> void VisitFields(V& v)` member.
//
//   PipelineOptions options;                      // defaults
//   LoadConfigYaml("configs/pl.yaml", &options);  // keys absent from the file keep defaults
//   ApplyOverrides(context.config_overrides, &options);  // {"tracking.max_iterations=30"}
//   CheckOptionsOrThrow(options, "config");       // throws when options.Check() is not empty
//   WriteConfigYaml(options, out_dir + "/config.yaml");  // the effective config
//
// Keys are dotted paths through Section()s ("tracking.solver"). A key that no field has is an
// error naming the key and the closest valid keys; so is a value of the wrong type or an enum
// name that does not exist (the message lists the valid names). YAML files hold sections as
// nested maps; bool as true/false, enums by name, vectors as [1, 2, 3]; overrides write vectors
// as "1,2,3". Files are read by core/yaml_reader.h (errors name the line); the "%YAML:1.0" first
// line that the writer puts is optional.
//
// The templates below only flatten a struct into a ConfigSchema (typed pointers to its fields
// with their dotted keys and docs); everything else is the non-template core in config_io.cc.
#ifndef PLDVO_CORE_CONFIG_IO_H_
#define PLDVO_CORE_CONFIG_IO_H_

#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "core/options.h"

namespace pldvo {

// An enum field seen through its names: the index of the current value in `names`, and a setter
// by index.
struct ChoiceRef {
  std::vector<std::string> names;
  std::function<int()> get_index;  // -1 when the value has no name
  std::function<void(int)> set_index;
};

struct ConfigEntry {
  std::string key;  // full dotted key
  std::string doc;
  std::variant<bool*, int*, double*, std::string*, std::vector<double>*, ChoiceRef> field;
};

struct ConfigSection {
  std::string key;  // full dotted key
  std::string doc;
};

// Every field of an options struct, in VisitFields order.
struct ConfigSchema {
  std::vector<ConfigEntry> entries;
  std::vector<ConfigSection> sections;
};

// The visitor that builds a ConfigSchema.
class ConfigSchemaBuilder {
 public:
  explicit ConfigSchemaBuilder(ConfigSchema* schema, std::string prefix = "")
      : schema_(schema), prefix_(std::move(prefix)) {}

  void Field(const std::string& name, bool* value, const std::string& doc) {
    Add(name, value, doc);
  }
  void Field(const std::string& name, int* value, const std::string& doc) { Add(name, value, doc); }
  void Field(const std::string& name, double* value, const std::string& doc) {
    Add(name, value, doc);
  }
  void Field(const std::string& name, std::string* value, const std::string& doc) {
    Add(name, value, doc);
  }
  void Field(const std::string& name, std::vector<double>* value, const std::string& doc) {
    Add(name, value, doc);
  }

  template <typename Enum>
  void Choice(const std::string& name, Enum* value, const ChoiceNames<Enum>& names,
              const std::string& doc) {
    ChoiceRef choice;
    for (const auto& name_value : names) choice.names.push_back(name_value.first);
    choice.get_index = [value, names]() {
      for (size_t i = 0; i < names.size(); ++i) {
        if (names[i].second == *value) return static_cast<int>(i);
      }
      return -1;
    };
    choice.set_index = [value, names](int index) { *value = names.at(index).second; };
    Add(name, std::move(choice), doc);
  }

  template <typename Sub>
  void Section(const std::string& name, Sub* sub_options, const std::string& doc) {
    schema_->sections.push_back({prefix_ + name, doc});
    ConfigSchemaBuilder sub_builder(schema_, prefix_ + name + ".");
    sub_options->VisitFields(sub_builder);
  }

 private:
  template <typename Ref>
  void Add(const std::string& name, Ref ref, const std::string& doc) {
    schema_->entries.push_back({prefix_ + name, doc, std::move(ref)});
  }

  ConfigSchema* schema_;
  std::string prefix_;
};

// The schema of `options`; its pointers refer into *options.
template <class Options>
ConfigSchema MakeConfigSchema(Options* options) {
  ConfigSchema schema;
  ConfigSchemaBuilder builder(&schema);
  options->VisitFields(builder);
  return schema;
}

// ---- Non-template core (config_io.cc) ----
// Throws std::runtime_error naming the file, the line and the dotted key.
void LoadConfigYaml(const std::string& path, const ConfigSchema& schema);
// Throws std::invalid_argument naming the override and the key.
void ApplyOverrides(const std::vector<std::string>& overrides, const ConfigSchema& schema);
std::string ConfigToString(const ConfigSchema& schema);
// Throws std::runtime_error when the file cannot be written.
void WriteConfigYaml(const ConfigSchema& schema, const std::string& path);
std::string DescribeConfig(const ConfigSchema& schema);

// ---- Templates over any struct with VisitFields ----
template <class Options>
void LoadConfigYaml(const std::string& path, Options* options) {
  LoadConfigYaml(path, MakeConfigSchema(options));
}

template <class Options>
void ApplyOverrides(const std::vector<std::string>& overrides, Options* options) {
  ApplyOverrides(overrides, MakeConfigSchema(options));
}

// YAML text with a comment per field (its doc) that LoadConfigYaml reads back to an equal struct.
template <class Options>
std::string ConfigToString(const Options& options) {
  Options copy = options;  // VisitFields is not const
  return ConfigToString(MakeConfigSchema(&copy));
}

template <class Options>
void WriteConfigYaml(const Options& options, const std::string& path) {
  Options copy = options;
  WriteConfigYaml(MakeConfigSchema(&copy), path);
}

// A Markdown table with columns key, type, default (the values in `options`), doc.
template <class Options>
std::string DescribeConfig(const Options& options) {
  Options copy = options;
  return DescribeConfig(MakeConfigSchema(&copy));
}

// Throws std::invalid_argument "<what>: <Check() message>" when options.Check() is not empty.
template <class Options>
void CheckOptionsOrThrow(const Options& options, const std::string& what) {
  const std::string error = options.Check();
  if (!error.empty()) throw std::invalid_argument(what + ": " + error);
}

}  // namespace pldvo

#endif  // PLDVO_CORE_CONFIG_IO_H_
