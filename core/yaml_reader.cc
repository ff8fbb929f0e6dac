// yaml-cpp rather than cv::FileStorage: a cv::FileNode has no line number (so EuRoC's sensor.yaml
// had its own line parser to name lines), FileStorage reads YAML from memory only after a
// prepended "%YAML:1.0", and its errors come as cv::Exception (or std::length_error) to unpick.
#include "core/yaml_reader.h"

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

namespace pldvo {
namespace {

// More nodes than any of our files has by far; bounds the key check below, which would
// otherwise visit an aliased node once per alias ("billion laughs").
constexpr int kMaxNodes = 100000;

[[noreturn]] void FailAt(const std::string& path, int line, const std::string& what) {
  throw std::runtime_error(path + (line > 0 ? ":" + std::to_string(line) : "") + ": " + what);
}

int LineOf(const YAML::Node& node) { return node.Mark().line + 1; }  // Mark is 0-based; -1: none

bool IsDigit(char c) { return c >= '0' && c <= '9'; }

// [+-]?[0-9]+
bool IsIntegerSpelling(const std::string& text) {
  size_t i = (!text.empty() && (text[0] == '+' || text[0] == '-')) ? 1 : 0;
  if (i == text.size()) return false;
  for (; i < text.size(); ++i) {
    if (!IsDigit(text[i])) return false;
  }
  return true;
}

// [+-]?([0-9]+(\.[0-9]*)?|\.[0-9]+)([eE][+-]?[0-9]+)?, or YAML's [+-]?.inf and .nan.
bool IsNumberSpelling(const std::string& text) {
  static const std::set<std::string> kSpecial = {".inf",  ".Inf",  ".INF",  "+.inf",
                                                 "+.Inf", "+.INF", "-.inf", "-.Inf",
                                                 "-.INF", ".nan",  ".NaN",  ".NAN"};
  if (kSpecial.count(text)) return true;
  size_t i = (!text.empty() && (text[0] == '+' || text[0] == '-')) ? 1 : 0;
  size_t digits = 0;
  while (i < text.size() && IsDigit(text[i])) ++i, ++digits;
  if (i < text.size() && text[i] == '.') {
    ++i;
    while (i < text.size() && IsDigit(text[i])) ++i, ++digits;
  }
  if (digits == 0) return false;
  if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    ++i;
    if (i < text.size() && (text[i] == '+' || text[i] == '-')) ++i;
    size_t exponent_digits = 0;
    while (i < text.size() && IsDigit(text[i])) ++i, ++exponent_digits;
    if (exponent_digits == 0) return false;
  }
  return i == text.size();
}

bool IsPlainScalar(const YAML::Node& node) { return node.IsScalar() && node.Tag() == "?"; }

// Our files are one map. yaml-cpp's Load reads the first document and ignores the rest, and it
// starts a new implicit document at a column-0 line after an indented top level, so a stray
// "---" or "..." or an indented first key would drop keys without a word: reject them here, with
// the line.
void RejectMultipleDocuments(const std::string& text, const std::string& path) {
  std::istringstream lines(text);
  std::string line;
  int line_number = 0;
  bool seen_marker = false, seen_content = false;
  while (std::getline(lines, line)) {
    ++line_number;
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    if (!seen_content && !seen_marker && line[0] == '%') continue;  // a directive
    if (line.compare(0, 3, "---") == 0) {
      if (seen_marker || seen_content) {
        FailAt(path, line_number, "only one YAML document is supported (second '---')");
      }
      const size_t rest = line.find_first_not_of(" \t\r", 3);
      if (rest != std::string::npos && (rest == 3 || line[rest] != '#')) {
        FailAt(path, line_number, "put the keys on the lines after '---'");
      }
      seen_marker = true;
      continue;
    }
    if (line.compare(0, 3, "...") == 0) {
      FailAt(path, line_number, "the document end marker '...' is not supported");
    }
    if (!seen_content && first != 0) {
      FailAt(path, line_number, "the top-level keys must start at column 0");
    }
    seen_content = true;
  }
}

// Records where each document starts and nothing else.
class DocumentStarts : public YAML::EventHandler {
 public:
  std::vector<YAML::Mark> marks;
  void OnDocumentStart(const YAML::Mark& mark) override { marks.push_back(mark); }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t,
                const std::string&) override {}
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}
};

// Where a second document starts, if the parser finds one. Asks for at most two documents:
// yaml-cpp 0.7's LoadAll loops for ever on a document that starts with ',' (jbeder/yaml-cpp
// #1040, fixed in 0.8), as its parser reports it again and again without consuming it.
std::optional<YAML::Mark> SecondDocumentStart(const std::string& text) {
  std::istringstream stream(text);
  YAML::Parser parser(stream);
  DocumentStarts starts;
  for (int i = 0; i < 2 && parser.HandleNextDocument(starts); ++i) {
  }
  if (starts.marks.size() < 2) return std::nullopt;
  return starts.marks[1];
}

// Every map key is a non-empty scalar, unique in its map.
void CheckKeys(const YAML::Node& node, const std::string& key, const std::string& path,
               int* budget) {
  if (--*budget < 0) {
    FailAt(path, 0, "more than " + std::to_string(kMaxNodes) + " YAML nodes (aliases?)");
  }
  if (node.IsSequence()) {
    for (const YAML::Node& item : node) CheckKeys(item, key, path, budget);
    return;
  }
  if (!node.IsMap()) return;
  std::set<std::string> seen;
  for (const auto& entry : node) {
    const YAML::Node& name = entry.first;
    if (!name.IsScalar() || name.Scalar().empty()) {
      FailAt(path, LineOf(name) > 0 ? LineOf(name) : LineOf(entry.second),
             "YAML syntax error: a key must be a non-empty name" +
                 std::string(key.empty() ? "" : " (in '" + key + "')"));
    }
    const std::string child = key.empty() ? name.Scalar() : key + "." + name.Scalar();
    if (!seen.insert(name.Scalar()).second) {
      FailAt(path, LineOf(name), "duplicate key '" + child + "'");
    }
    CheckKeys(entry.second, child, path, budget);
  }
}

}  // namespace

YamlNode::YamlNode(std::string path, std::string key, std::string name,
                   std::shared_ptr<const YAML::Node> node, int line)
    : path_(std::move(path)),
      key_(std::move(key)),
      name_(std::move(name)),
      node_(std::move(node)),
      line_(line) {}

YamlNode YamlNode::ReadFile(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw std::runtime_error(path + ": cannot open the file for reading");
  std::ostringstream content;
  content << file.rdbuf();
  const std::string text = content.str();
  RejectMultipleDocuments(text, path);
  YAML::Node document;
  std::optional<YAML::Mark> second_document;
  try {
    document = YAML::Load(text);
    second_document = SecondDocumentStart(text);
  } catch (const YAML::ParserException& error) {  // also yaml-cpp's nesting limit
    FailAt(path, error.mark.line + 1, "YAML syntax error: " + error.msg);
  } catch (const std::exception& error) {
    FailAt(path, 0, std::string("YAML syntax error: ") + error.what());
  }
  if (second_document) {  // no second "---" (checked above): content the parser did not read
    FailAt(path, second_document->line + 1, "YAML syntax error: content after the document");
  }
  auto root = std::make_shared<YAML::Node>(document);
  int budget = kMaxNodes;
  CheckKeys(*root, "", path, &budget);
  return YamlNode(path, "", "", root, std::max(1, LineOf(*root)));
}

int YamlNode::line() const { return line_; }
bool YamlNode::IsNull() const { return node_->IsNull(); }
bool YamlNode::IsMap() const { return node_->IsMap(); }
bool YamlNode::IsList() const { return node_->IsSequence(); }
bool YamlNode::IsScalar() const { return node_->IsScalar(); }

std::vector<YamlNode> YamlNode::Entries() const {
  std::vector<YamlNode> entries;
  if (!node_->IsMap()) return entries;
  for (const auto& entry : *node_) {
    const std::string name = entry.first.Scalar();  // a non-empty scalar (CheckKeys)
    // The key's line: a block map or list as the value starts on the next line.
    entries.push_back(YamlNode(path_, key_.empty() ? name : key_ + "." + name, name,
                               std::make_shared<const YAML::Node>(entry.second),
                               LineOf(entry.first)));
  }
  return entries;
}

std::optional<YamlNode> YamlNode::Find(const std::string& name) const {
  for (YamlNode& entry : Entries()) {
    if (entry.name() == name) return std::move(entry);
  }
  return std::nullopt;
}

std::vector<YamlNode> YamlNode::Items() const {
  std::vector<YamlNode> items;
  if (!node_->IsSequence()) return items;
  for (const YAML::Node& item : *node_) {
    const int line = LineOf(item);
    items.push_back(YamlNode(path_, key_, name_, std::make_shared<const YAML::Node>(item),
                             line > 0 ? line : line_));
  }
  return items;
}

bool YamlNode::GetString(std::string* value) const {
  if (!node_->IsScalar()) return false;
  if (IsPlainScalar(*node_) && IsNumberSpelling(node_->Scalar())) return false;
  *value = node_->Scalar();
  return true;
}

bool YamlNode::GetInt(int* value) const {
  if (!IsPlainScalar(*node_) || !IsIntegerSpelling(node_->Scalar())) return false;
  errno = 0;
  const long long parsed = std::strtoll(node_->Scalar().c_str(), nullptr, 10);
  if (errno == ERANGE || parsed < std::numeric_limits<int>::min() ||
      parsed > std::numeric_limits<int>::max()) {
    return false;
  }
  *value = static_cast<int>(parsed);
  return true;
}

bool YamlNode::GetDouble(double* value) const {
  if (!IsPlainScalar(*node_) || !IsNumberSpelling(node_->Scalar())) return false;
  std::string text = node_->Scalar();
  const size_t dot = text.find('.');
  if (dot != std::string::npos && dot + 1 < text.size() && !IsDigit(text[dot + 1]) &&
      (text[dot + 1] | 0x20) != 'e') {
    text.erase(dot, 1);  // ".inf" -> "inf", "-.inf" -> "-inf", ".nan" -> "nan" for strtod
  }
  *value = std::strtod(text.c_str(), nullptr);  // overflow gives +-inf, as in the spelling
  return true;
}

bool YamlNode::GetBool(bool* value) const {
  if (!node_->IsScalar()) return false;
  std::string lower = node_->Scalar();
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  int number = -1;
  if (lower == "true" || lower == "false" || lower == "1" || lower == "0") {
    *value = lower == "true" || lower == "1";
    return true;
  }
  if (GetInt(&number) && (number == 0 || number == 1)) {  // "+1", "01"
    *value = number == 1;
    return true;
  }
  return false;
}

std::string YamlNode::Describe() const {
  if (node_->IsMap()) return "a map";
  if (node_->IsSequence()) return "a list";
  if (!node_->IsScalar()) return "no value";
  const std::string& text = node_->Scalar();
  if (IsPlainScalar(*node_) && IsIntegerSpelling(text)) return "the integer " + text;
  if (IsPlainScalar(*node_) && IsNumberSpelling(text)) return "the number " + text;
  return "the string '" + text + "'";
}

void YamlNode::Fail(const std::string& what) const {
  FailAt(path_, line_, key_.empty() ? what : "key '" + key_ + "': " + what);
}

void YamlNode::FailAtLine(const std::string& what) const { FailAt(path_, line_, what); }

}  // namespace pldvo
