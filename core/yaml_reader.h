// The one reader of YAML files: the configs (core/config_io.h), camera.yaml (core/camera_yaml.h)
// and EuRoC's sensor.yaml (core/euroc_dataset.cc). yaml-cpp parses; this layer adds the path and
// the line to every error, and reads scalars by their spelling:
//   integer   a plain (unquoted) scalar of digits with an optional sign: 20, -3
//   number    an integer, or a plain decimal like 0.5, -1e-8, 20., or .inf, -.inf, .nan
//   bool      true / false / 1 / 0 (any case), as the config overrides spell them
//   string    a quoted scalar, or a plain one that is not a number ("00" and "12" are strings,
//             00 and 12 are integers)
//
//   const YamlNode root = YamlNode::ReadFile(path);  // throws "<path>:<line>: YAML syntax error"
//   for (const YamlNode& entry : root.Entries()) {    // entry.name(), entry.key() ("a.b")
//     int value = 0;
//     if (!entry.GetInt(&value)) entry.Fail("expected an integer, got " + entry.Describe());
//   }
//
// A file holds one document whose top level starts at column 0; every map key is a non-empty
// plain name, unique within its map. Errors are std::runtime_error naming the file and, where
// the node has one, the line (1-based).
#ifndef PLDVO_CORE_YAML_READER_H_
#define PLDVO_CORE_YAML_READER_H_

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace YAML {
class Node;
}  // namespace YAML

namespace pldvo {

class YamlNode {
 public:
  // The top-level node of the file; a file with no content gives a null node. Throws
  // std::runtime_error when the file cannot be read or is not YAML as described above.
  static YamlNode ReadFile(const std::string& path);

  const std::string& path() const { return path_; }
  // The dotted key from the top level ("tracking.solver.kind"); "" for the top level. List
  // elements carry the key of their list.
  const std::string& key() const { return key_; }
  // The node's key in its map: the last component of key() (itself dotted if the file's key is).
  const std::string& name() const { return name_; }
  // The 1-based line of the node: for a map entry the line of its key (a block value starts on
  // the next one), for a list element its own; 0 when unknown.
  int line() const;

  bool IsNull() const;  // "key:" with no value, "~" or "null"
  bool IsMap() const;
  bool IsList() const;
  bool IsScalar() const;

  // The entries of a map in file order; empty for a node that is not a map.
  std::vector<YamlNode> Entries() const;
  // The entry `name` of a map; nullopt when absent or when this is not a map.
  std::optional<YamlNode> Find(const std::string& name) const;
  // The elements of a list; empty for a node that is not a list.
  std::vector<YamlNode> Items() const;

  // Scalar conversions by spelling (header comment); false, leaving *value alone, when the node
  // is not such a scalar (or the integer does not fit an int).
  bool GetString(std::string* value) const;
  bool GetInt(int* value) const;
  bool GetDouble(double* value) const;
  bool GetBool(bool* value) const;

  // For messages: "a map", "a list", "the string 'x'", "the integer 3", "the number 2.5",
  // "no value".
  std::string Describe() const;

  // Throw std::runtime_error("<path>:<line>: key '<key>': <what>"); at the top level, and for
  // FailAtLine always, "<path>:<line>: <what>".
  [[noreturn]] void Fail(const std::string& what) const;
  [[noreturn]] void FailAtLine(const std::string& what) const;

 private:
  YamlNode(std::string path, std::string key, std::string name,
           std::shared_ptr<const YAML::Node> node, int line);

  std::string path_;
  std::string key_;
  std::string name_;
  std::shared_ptr<const YAML::Node> node_;  // yaml-cpp stays out of this header
  int line_ = 0;
};

}  // namespace pldvo

#endif  // PLDVO_CORE_YAML_READER_H_
