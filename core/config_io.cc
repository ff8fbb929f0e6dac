#include "core/config_io.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <opencv2/core.hpp>
#include <set>
#include <sstream>

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

// The shortest decimal that reads back to exactly `value` (YAML spellings for inf and nan, which
// cv::FileStorage reads as reals).
std::string FormatDouble(double value) {
  if (std::isnan(value)) return ".nan";
  if (std::isinf(value)) return value > 0 ? ".inf" : "-.inf";
  char buffer[64];
  for (int precision = 1; precision <= 17; ++precision) {
    std::snprintf(buffer, sizeof(buffer), "%.*g", precision, value);
    if (std::strtod(buffer, nullptr) == value) break;
  }
  std::string text = buffer;
  // Keep a real-looking spelling so the YAML type is "real" (cv reads "20" as an integer).
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
      // cv::FileStorage reads no control character back (WriteConfigYaml must round-trip).
      for (char c : text) {
        if (static_cast<unsigned char>(c) < 0x20) return "control characters are not allowed";
      }
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

std::string DescribeNode(const cv::FileNode& node) {
  if (node.isMap()) return "a map";
  if (node.isSeq()) return "a list";
  if (node.isString()) return "the string '" + static_cast<std::string>(node) + "'";
  if (node.isInt()) return "the integer " + std::to_string(static_cast<int>(node));
  if (node.isReal()) return "the number " + FormatDouble(static_cast<double>(node));
  return "no value";
}

bool NodeIsNumber(const cv::FileNode& node) { return node.isInt() || node.isReal(); }

// Sets an entry from a YAML node; returns "" or what is wrong.
std::string SetFromNode(const ConfigEntry& entry, const cv::FileNode& node) {
  struct Visitor {
    const cv::FileNode& node;
    std::string operator()(bool* value) const {
      if (node.isString() && ParseBool(static_cast<std::string>(node), value)) return "";
      if (node.isInt() && (static_cast<int>(node) == 0 || static_cast<int>(node) == 1)) {
        *value = static_cast<int>(node) == 1;
        return "";
      }
      return "expected true or false, got " + DescribeNode(node);
    }
    std::string operator()(int* value) const {
      if (!node.isInt()) return "expected an integer, got " + DescribeNode(node);
      *value = static_cast<int>(node);
      return "";
    }
    std::string operator()(double* value) const {
      if (!NodeIsNumber(node)) return "expected a number, got " + DescribeNode(node);
      *value = static_cast<double>(node);
      return "";
    }
    std::string operator()(std::string* value) const {
      if (!node.isString()) {
        return "expected a string (quote it: \"...\"), got " + DescribeNode(node);
      }
      *value = static_cast<std::string>(node);
      return "";
    }
    std::string operator()(std::vector<double>* value) const {
      if (!node.isSeq()) return "expected a list of numbers like [1, 2], got " + DescribeNode(node);
      std::vector<double> values;
      for (cv::FileNodeIterator it = node.begin(); it != node.end(); ++it) {
        const cv::FileNode item = *it;
        if (!NodeIsNumber(item)) {
          return "expected a list of numbers, element " + std::to_string(values.size()) + " is " +
                 DescribeNode(item);
        }
        values.push_back(static_cast<double>(item));
      }
      *value = values;
      return "";
    }
    std::string operator()(const ChoiceRef& choice) const {
      if (!node.isString()) {
        return "expected one of " + Join(choice.names, ", ") + ", got " + DescribeNode(node);
      }
      return SetFromText(ConfigEntry{"", "", choice}, static_cast<std::string>(node));
    }
  };
  return std::visit(Visitor{node}, entry.field);
}

void ReadMap(const cv::FileNode& map, const std::string& prefix, const ConfigSchema& schema,
             const std::string& path) {
  auto fail = [&path](const std::string& message) {
    throw std::runtime_error(path + ": " + message);
  };
  std::set<std::string> seen;
  for (cv::FileNodeIterator it = map.begin(); it != map.end(); ++it) {
    const cv::FileNode node = *it;
    const std::string key = prefix + node.name();
    if (!seen.insert(node.name()).second) fail("duplicate key '" + key + "'");
    if (IsSection(schema, key)) {
      if (!node.isMap()) {
        fail("key '" + key + "' is a section and takes a map of its keys (" +
             Join(KeysAtLevel(schema, key), ", ") + "), got " + DescribeNode(node));
      }
      ReadMap(node, key + ".", schema, path);
      continue;
    }
    const ConfigEntry* entry = FindEntry(schema, key);
    if (entry == nullptr) fail(UnknownKeyMessage(schema, key));
    const std::string error = SetFromNode(*entry, node);
    if (!error.empty()) fail("key '" + key + "': " + error);
  }
}

// ---- YAML writing ----

void WriteComment(const std::string& doc, const std::string& indent, std::ostringstream* out) {
  std::stringstream lines(doc);
  std::string line;
  while (std::getline(lines, line)) *out << indent << "# " << line << "\n";
}

// cv::FileStorage (OpenCV 4.6 persistence_yml.cpp, YAMLParser::parse) loops forever when a
// second YAML document starts with '-' other than "---" ("a: 1\n...\n- 1"), which an indented
// root map ended by a line at column 0 also reaches ("  a: 1\nb\n-"). Our files are one map,
// so reject what leads to a second document: a second "---", a "...", keys on the "---" line,
// and an indented first key. Found by tests/fuzz/camera_yaml_fuzzer (docs/reliability.md).
void RejectMultipleDocuments(const std::string& text, const std::string& path) {
  std::istringstream lines(text);
  std::string line;
  int line_number = 0;
  bool seen_marker = false, seen_content = false;
  auto fail = [&](const std::string& what) {
    throw std::runtime_error(path + ":" + std::to_string(line_number) + ": " + what);
  };
  while (std::getline(lines, line)) {
    ++line_number;
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    if (!seen_content && !seen_marker && line[0] == '%') continue;  // a directive
    if (line.compare(0, 3, "---") == 0) {
      if (seen_marker || seen_content) fail("only one YAML document is supported (second '---')");
      const size_t rest = line.find_first_not_of(" \t\r", 3);
      if (rest != std::string::npos && (rest == 3 || line[rest] != '#')) {
        fail("put the keys on the lines after '---'");
      }
      seen_marker = true;
      continue;
    }
    if (line.compare(0, 3, "...") == 0) fail("the document end marker '...' is not supported");
    if (!seen_content && first != 0) fail("the top-level keys must start at column 0");
    seen_content = true;
  }
}

}  // namespace

void OpenYamlForReading(const std::string& path, cv::FileStorage* storage) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw std::runtime_error(path + ": cannot open the file for reading");
  std::ostringstream content;
  content << file.rdbuf();
  std::string text = content.str();
  RejectMultipleDocuments(text, path);
  // cv::FileStorage needs the "%YAML" directive to recognise YAML in memory; add it if missing.
  int added_lines = 0;
  if (text.compare(0, 5, "%YAML") != 0) {
    if (text.compare(0, 3, "---") == 0) {
      text = "%YAML:1.0\n" + text;
      added_lines = 1;
    } else {
      text = "%YAML:1.0\n---\n" + text;
      added_lines = 2;
    }
  }
  try {
    storage->open(text,
                  cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  } catch (const cv::Exception& error) {
    // Parse errors carry "(line): message" in error.func.
    std::string message = error.func;
    int line = 0;
    char rest[512] = {0};
    if (std::sscanf(error.func.c_str(), "(%d): %511[^\n]", &line, rest) == 2) {
      throw std::runtime_error(path + ":" + std::to_string(line - added_lines) +
                               ": YAML syntax error: " + rest);
    }
    throw std::runtime_error(path + ": YAML syntax error: " + error.err + " " + message);
  } catch (const std::exception& error) {
    // OpenCV 4.6's parser also lets std::length_error out (an empty key "  :" in a nested map).
    throw std::runtime_error(path + ": YAML syntax error: " + error.what());
  }
  if (!storage->isOpened()) throw std::runtime_error(path + ": cannot parse the file as YAML");
}

void LoadConfigYaml(const std::string& path, const ConfigSchema& schema) {
  cv::FileStorage storage;
  OpenYamlForReading(path, &storage);
  const cv::FileNode root = storage.root();
  if (root.empty() || root.isNone()) return;  // an empty file keeps every default
  if (!root.isMap()) {
    throw std::runtime_error(path + ": the top level must be a map of keys, got " +
                             DescribeNode(root));
  }
  ReadMap(root, "", schema, path);
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
