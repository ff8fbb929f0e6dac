#include "core/config_io.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include "core/yaml_reader.h"

namespace pldvo {
namespace {

// ---- Text helpers ----

std::string Trim(const std::string& text) {
  const size_t begin = text.find_first_not_of(" \t\r\n");
  if (begin == std::string::npos) return "";
  const size_t end = text.find_last_not_of(" \t\r\n");
  return text.substr(begin, end - begin + 1);
}

std::string Join(const std::vector<std::string>& items, const std::string& separator) {
  std::string joined;
  for (size_t i = 0; i < items.size(); ++i) joined += (i ? separator : "") + items[i];
  return joined;
}

std::string ParentKey(const std::string& key) {
  const size_t dot = key.rfind('.');
  return dot == std::string::npos ? "" : key.substr(0, dot);
}

std::string LeafName(const std::string& key) {
  const size_t dot = key.rfind('.');
  return dot == std::string::npos ? key : key.substr(dot + 1);
}

// The shortest decimal that reads back to exactly `value` (YAML spellings for inf and nan).
std::string FormatDouble(double value) {
  if (std::isnan(value)) return ".nan";
  if (std::isinf(value)) return value > 0 ? ".inf" : "-.inf";
  char buffer[64];
  for (int precision = 1; precision <= 17; ++precision) {
    std::snprintf(buffer, sizeof(buffer), "%.*g", precision, value);
    if (std::strtod(buffer, nullptr) == value) break;
  }
  std::string text = buffer;
  // Keep a real-looking spelling, so that OpenCV's reader too sees a real ("20" is an integer).
  if (text.find_first_of(".eE") == std::string::npos) text += ".0";
  return text;
}

std::string FormatVector(const std::vector<double>& values) {
  std::string text = "[";
  for (size_t i = 0; i < values.size(); ++i) text += (i ? ", " : "") + FormatDouble(values[i]);
  return text + "]";
}

std::string Quote(const std::string& text) {
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') quoted += '\\';
    quoted += c;
  }
  return quoted + "\"";
}

bool ParseBool(const std::string& text, bool* value) {
  std::string lower = text;
  std::transform(lower.begin(), lower.end(), lower.begin(), ::tolower);
  if (lower == "true" || lower == "1") {
    *value = true;
    return true;
  }
  if (lower == "false" || lower == "0") {
    *value = false;
    return true;
  }
  return false;
}

bool ParseInt(const std::string& text, int* value) {
  if (text.empty()) return false;
  errno = 0;
  char* end = nullptr;
  const long parsed = std::strtol(text.c_str(), &end, 10);
  if (*end != '\0' || errno == ERANGE || parsed < std::numeric_limits<int>::min() ||
      parsed > std::numeric_limits<int>::max()) {
    return false;
  }
  *value = static_cast<int>(parsed);
  return true;
}

bool ParseDouble(const std::string& text, double* value) {
  if (text.empty()) return false;
  std::string spelling = text;
  if (spelling == ".inf" || spelling == "+.inf") spelling = "inf";
  if (spelling == "-.inf") spelling = "-inf";
  if (spelling == ".nan") spelling = "nan";
  char* end = nullptr;
  const double parsed = std::strtod(spelling.c_str(), &end);
  if (*end != '\0') return false;
  *value = parsed;
  return true;
}

// Levenshtein distance, for "did you mean".
size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1] ? 1 : 0)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// ---- Schema helpers ----

const ConfigEntry* FindEntry(const ConfigSchema& schema, const std::string& key) {
  for (const ConfigEntry& entry : schema.entries) {
    if (entry.key == key) return &entry;
  }
  return nullptr;
}

bool IsSection(const ConfigSchema& schema, const std::string& key) {
  for (const ConfigSection& section : schema.sections) {
    if (section.key == key) return true;
  }
  return false;
}

// The names directly inside section `prefix` ("" for the top level), sections marked with ".".
std::vector<std::string> KeysAtLevel(const ConfigSchema& schema, const std::string& prefix) {
  std::vector<std::string> keys;
  for (const ConfigSection& section : schema.sections) {
    if (ParentKey(section.key) == prefix) keys.push_back(LeafName(section.key) + ".*");
  }
  for (const ConfigEntry& entry : schema.entries) {
    if (ParentKey(entry.key) == prefix) keys.push_back(LeafName(entry.key));
  }
  return keys;
}

// "unknown key 'a.b' (did you mean 'a.c'?); valid keys in 'a': c, d".
std::string UnknownKeyMessage(const ConfigSchema& schema, const std::string& key) {
  std::ostringstream message;
  message << "unknown key '" << key << "'";
  std::vector<std::string> closest;
  size_t best = std::numeric_limits<size_t>::max();
  auto consider = [&](const std::string& candidate) {
    const size_t distance = EditDistance(key, candidate);
    if (distance < best) {
      best = distance;
      closest.clear();
    }
    if (distance == best) closest.push_back("'" + candidate + "'");
  };
  for (const ConfigSection& section : schema.sections) consider(section.key);
  for (const ConfigEntry& entry : schema.entries) consider(entry.key);
  if (!closest.empty() && best <= std::max<size_t>(2, key.size() / 3)) {
    message << " (did you mean " << Join(closest, " or ") << "?)";
  }
  // The deepest existing section that prefixes the key.
  std::string level = ParentKey(key);
  while (!level.empty() && !IsSection(schema, level)) level = ParentKey(level);
  message << "; valid keys " << (level.empty() ? "at the top level" : "in '" + level + "'") << ": "
          << Join(KeysAtLevel(schema, level), ", ");
  return message.str();
}

std::string TypeName(const ConfigEntry& entry) {
  struct Visitor {
    std::string operator()(bool*) const { return "bool"; }
    std::string operator()(int*) const { return "int"; }
    std::string operator()(double*) const { return "double"; }
    std::string operator()(std::string*) const { return "string"; }
    std::string operator()(std::vector<double>*) const { return "list of double"; }
    std::string operator()(const ChoiceRef& choice) const {
      return "one of " + Join(choice.names, ", ");
    }
  };
  return std::visit(Visitor(), entry.field);
}

std::string ChoiceName(const ChoiceRef& choice) {
  const int index = choice.get_index();
  return index >= 0 ? choice.names[index] : "<unnamed value>";
}

// WriteConfigYaml must round-trip, and YAML folds or rejects a raw control character in a
// scalar, so string values from a file (escapes such as "\n") or an override may hold none.
const char kControlCharacterError[] = "control characters are not allowed";
bool HasControlCharacter(const std::string& text) {
  return std::any_of(text.begin(), text.end(),
                     [](char c) { return static_cast<unsigned char>(c) < 0x20; });
}

// The value as YAML text.
std::string YamlValue(const ConfigEntry& entry) {
  struct Visitor {
    std::string operator()(bool* value) const { return *value ? "true" : "false"; }
    std::string operator()(int* value) const { return std::to_string(*value); }
    std::string operator()(double* value) const { return FormatDouble(*value); }
    std::string operator()(std::string* value) const { return Quote(*value); }
    std::string operator()(std::vector<double>* value) const { return FormatVector(*value); }
    std::string operator()(const ChoiceRef& choice) const { return ChoiceName(choice); }
  };
  return std::visit(Visitor(), entry.field);
}

// Sets an entry from override text; returns "" or what is wrong.
std::string SetFromText(const ConfigEntry& entry, const std::string& text) {
  struct Visitor {
    const std::string& text;
    std::string operator()(bool* value) const {
      return ParseBool(text, value) ? "" : "expected true or false, got '" + text + "'";
    }
    std::string operator()(int* value) const {
      return ParseInt(text, value) ? "" : "expected an integer, got '" + text + "'";
    }
    std::string operator()(double* value) const {
      return ParseDouble(text, value) ? "" : "expected a number, got '" + text + "'";
    }
    std::string operator()(std::string* value) const {
      if (HasControlCharacter(text)) return kControlCharacterError;
      *value = text;
      return "";
    }
    std::string operator()(std::vector<double>* value) const {
      std::string list = text;
      if (list.size() >= 2 && list.front() == '[' && list.back() == ']') {
        list = Trim(list.substr(1, list.size() - 2));
      }
      std::vector<double> values;
      if (!list.empty()) {
        std::stringstream stream(list);
        std::string item;
        while (std::getline(stream, item, ',')) {
          double number = 0.0;
          if (!ParseDouble(Trim(item), &number)) {
            return "expected comma-separated numbers like 1,2.5,3, got '" + text + "'";
          }
          values.push_back(number);
        }
      }
      *value = values;
      return "";
    }
    std::string operator()(const ChoiceRef& choice) const {
      for (size_t i = 0; i < choice.names.size(); ++i) {
        if (choice.names[i] == text) {
          choice.set_index(static_cast<int>(i));
          return "";
        }
      }
      return "unknown value '" + text + "'; valid: " + Join(choice.names, ", ");
    }
  };
  return std::visit(Visitor{text}, entry.field);
}

// ---- YAML reading ----

// Sets an entry from a YAML node; returns "" or what is wrong.
std::string SetFromNode(const ConfigEntry& entry, const YamlNode& node) {
  struct Visitor {
    const YamlNode& node;
    std::string operator()(bool* value) const {
      return node.GetBool(value) ? "" : "expected true or false, got " + node.Describe();
    }
    std::string operator()(int* value) const {
      return node.GetInt(value) ? "" : "expected an integer, got " + node.Describe();
    }
    std::string operator()(double* value) const {
      return node.GetDouble(value) ? "" : "expected a number, got " + node.Describe();
    }
    std::string operator()(std::string* value) const {
      std::string text;
      if (!node.GetString(&text)) {
        return "expected a string (quote it: \"...\"), got " + node.Describe();
      }
      if (HasControlCharacter(text)) return kControlCharacterError;
      *value = text;
      return "";
    }
    std::string operator()(std::vector<double>* value) const {
      if (!node.IsList()) return "expected a list of numbers like [1, 2], got " + node.Describe();
      std::vector<double> values;
      for (const YamlNode& item : node.Items()) {
        double number = 0.0;
        if (!item.GetDouble(&number)) {
          return "expected a list of numbers, element " + std::to_string(values.size()) + " is " +
                 item.Describe();
        }
        values.push_back(number);
      }
      *value = values;
      return "";
    }
    std::string operator()(const ChoiceRef& choice) const {
      std::string name;
      if (!node.GetString(&name)) {
        return "expected one of " + Join(choice.names, ", ") + ", got " + node.Describe();
      }
      return SetFromText(ConfigEntry{"", "", choice}, name);
    }
  };
  return std::visit(Visitor{node}, entry.field);
}

// Keys are the map's dotted prefix plus the file's key (itself possibly dotted: "a.b: 1" at the
// top level sets a.b).
void ReadMap(const YamlNode& map, const std::string& prefix, const ConfigSchema& schema) {
  for (const YamlNode& node : map.Entries()) {
    const std::string key = prefix + node.name();
    if (IsSection(schema, key)) {
      if (!node.IsMap()) {
        node.FailAtLine("key '" + key + "' is a section and takes a map of its keys (" +
                        Join(KeysAtLevel(schema, key), ", ") + "), got " + node.Describe());
      }
      ReadMap(node, key + ".", schema);
      continue;
    }
    const ConfigEntry* entry = FindEntry(schema, key);
    if (entry == nullptr) node.FailAtLine(UnknownKeyMessage(schema, key));
    const std::string error = SetFromNode(*entry, node);
    if (!error.empty()) node.FailAtLine("key '" + key + "': " + error);
  }
}

// ---- YAML writing ----

void WriteComment(const std::string& doc, const std::string& indent, std::ostringstream* out) {
  std::stringstream lines(doc);
  std::string line;
  while (std::getline(lines, line)) *out << indent << "# " << line << "\n";
}

}  // namespace

void LoadConfigYaml(const std::string& path, const ConfigSchema& schema) {
  const YamlNode root = YamlNode::ReadFile(path);
  if (root.IsNull()) return;  // an empty file keeps every default
  if (!root.IsMap()) root.FailAtLine("the top level must be a map of keys, got " + root.Describe());
  ReadMap(root, "", schema);
}

void ApplyOverrides(const std::vector<std::string>& overrides, const ConfigSchema& schema) {
  for (const std::string& assignment : overrides) {
    const size_t equals = assignment.find('=');
    if (equals == std::string::npos) {
      throw std::invalid_argument("override '" + assignment + "' is not of the form key=value");
    }
    const std::string key = Trim(assignment.substr(0, equals));
    const std::string value = Trim(assignment.substr(equals + 1));
    const ConfigEntry* entry = FindEntry(schema, key);
    if (entry == nullptr) {
      if (IsSection(schema, key)) {
        throw std::invalid_argument(
            "override '" + assignment + "': '" + key +
            "' is a section; set one of its keys: " + Join(KeysAtLevel(schema, key), ", "));
      }
      throw std::invalid_argument("override '" + assignment +
                                  "': " + UnknownKeyMessage(schema, key));
    }
    const std::string error = SetFromText(*entry, value);
    if (!error.empty()) {
      throw std::invalid_argument("override '" + assignment + "': key '" + key + "': " + error);
    }
  }
}

std::string ConfigToString(const ConfigSchema& schema) {
  std::ostringstream out;
  out << "%YAML:1.0\n---\n";
  std::vector<std::string> open_sections;  // the chain of sections currently open
  for (const ConfigEntry& entry : schema.entries) {
    const std::string parent = ParentKey(entry.key);
    // Close sections that do not contain this entry, then open the missing ones.
    while (!open_sections.empty() && parent != open_sections.back() &&
           parent.compare(0, open_sections.back().size() + 1, open_sections.back() + ".") != 0) {
      open_sections.pop_back();
    }
    std::vector<std::string> to_open;
    for (std::string section = parent;
         !section.empty() && (open_sections.empty() || section != open_sections.back());
         section = ParentKey(section)) {
      to_open.push_back(section);
    }
    for (auto it = to_open.rbegin(); it != to_open.rend(); ++it) {
      const std::string indent(2 * open_sections.size(), ' ');
      for (const ConfigSection& section : schema.sections) {
        if (section.key == *it && !section.doc.empty()) WriteComment(section.doc, indent, &out);
      }
      out << indent << LeafName(*it) << ":\n";
      open_sections.push_back(*it);
    }
    const std::string indent(2 * open_sections.size(), ' ');
    if (!entry.doc.empty()) WriteComment(entry.doc, indent, &out);
    if (const ChoiceRef* choice = std::get_if<ChoiceRef>(&entry.field)) {
      out << indent << "# one of: " << Join(choice->names, ", ") << "\n";
    }
    out << indent << LeafName(entry.key) << ": " << YamlValue(entry) << "\n";
  }
  return out.str();
}

void WriteConfigYaml(const ConfigSchema& schema, const std::string& path) {
  std::ofstream file(path);
  if (!file) throw std::runtime_error(path + ": cannot open the file for writing");
  file << ConfigToString(schema);
  file.close();
  if (!file) throw std::runtime_error(path + ": write failed");
}

std::string DescribeConfig(const ConfigSchema& schema) {
  auto cell = [](std::string text) {
    std::string escaped;
    for (char c : text) {
      if (c == '|') escaped += '\\';
      escaped += (c == '\n') ? ' ' : c;
    }
    return escaped;
  };
  std::ostringstream out;
  out << "| key | type | default | doc |\n| --- | --- | --- | --- |\n";
  std::set<std::string> described_sections;
  for (const ConfigEntry& entry : schema.entries) {
    // Describe each enclosing section once, before its first field.
    std::vector<std::string> parents;
    for (std::string parent = ParentKey(entry.key); !parent.empty(); parent = ParentKey(parent)) {
      parents.insert(parents.begin(), parent);
    }
    for (const std::string& parent : parents) {
      if (!described_sections.insert(parent).second) continue;
      std::string doc;
      for (const ConfigSection& section : schema.sections) {
        if (section.key == parent) doc = section.doc;
      }
      out << "| **`" << parent << "`** | section | | " << cell(doc) << " |\n";
    }
    std::string value = YamlValue(entry);
    out << "| `" << entry.key << "` | " << cell(TypeName(entry)) << " | `" << cell(value) << "` | "
        << cell(entry.doc) << " |\n";
  }
  return out.str();
}

}  // namespace pldvo
