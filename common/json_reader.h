#pragma once
// Reading JSON input files with errors that name the file and the field.
//
//   JsonNode root = ParseJsonFile("rigs/theater4.json");
//   double fx = root["cameras"][0].Get<double>("fx");   // throws InputError
//                                                       // "rigs/theater4.json: cameras[0].fx: ..."

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "common/error.h"

namespace irbench {

class JsonNode {
 public:
  JsonNode(std::shared_ptr<const nlohmann::json> doc,
           const nlohmann::json* node,
           std::string file,
           std::string path);

  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }
  const nlohmann::json& raw() const { return *node_; }

  bool Has(const std::string& key) const;
  // Child object member; throws if missing.
  JsonNode operator[](const std::string& key) const;
  // Array element; throws if out of range or not an array.
  JsonNode operator[](size_t index) const;
  size_t Size() const;  // array length; throws if not an array
  std::vector<std::string> Keys() const;  // object keys in file order; throws if not an object

  double Number() const;
  int Int() const;
  bool Bool() const;
  std::string String() const;
  Eigen::Vector3d Vec3() const;
  Eigen::Vector2d Vec2() const;
  std::vector<double> Numbers() const;
  // An array of `size` finite numbers; an array of `rows` arrays of `cols`
  // finite numbers (model files' vectors and matrices).
  Eigen::VectorXd FiniteVector(int size) const;
  Eigen::MatrixXd FiniteMatrix(int rows, int cols) const;

  double GetDouble(const std::string& key) const { return (*this)[key].Number(); }
  double GetDouble(const std::string& key, double fallback) const;
  int GetInt(const std::string& key) const { return (*this)[key].Int(); }
  int GetInt(const std::string& key, int fallback) const;
  bool GetBool(const std::string& key, bool fallback) const;
  std::string GetString(const std::string& key) const { return (*this)[key].String(); }
  std::string GetString(const std::string& key, const std::string& fallback) const;
  Eigen::Vector3d GetVec3(const std::string& key) const { return (*this)[key].Vec3(); }

  // Throws InputError for this node's field.
  [[noreturn]] void Fail(const std::string& message) const;
  // Rejects keys not in `allowed` so that typos do not pass silently.
  void CheckKeys(const std::vector<std::string>& allowed) const;

 private:
  std::shared_ptr<const nlohmann::json> doc_;
  const nlohmann::json* node_;
  std::string file_;
  std::string path_;
};

// Parses a JSON file; a missing file or a syntax error (truncated file) throws
// InputError naming the file and line.
JsonNode ParseJsonFile(const std::string& path);
JsonNode ParseJsonString(const std::string& text, const std::string& name);

}  // namespace irbench
