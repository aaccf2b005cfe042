#include "common/json_reader.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

namespace irbench {

JsonNode::JsonNode(std::shared_ptr<const nlohmann::json> doc,
                   const nlohmann::json* node,
                   std::string file,
                   std::string path)
    : doc_(std::move(doc)), node_(node), file_(std::move(file)), path_(std::move(path)) {}

void JsonNode::Fail(const std::string& message) const {
  throw InputError(file_, path_.empty() ? "(document)" : path_, message);
}

bool JsonNode::Has(const std::string& key) const {
  return node_->is_object() && node_->contains(key) && !(*node_)[key].is_null();
}

JsonNode JsonNode::operator[](const std::string& key) const {
  const std::string child_path = path_.empty() ? key : path_ + "." + key;
  if (!node_->is_object()) Fail("expected an object");
  auto it = node_->find(key);
  if (it == node_->end() || it->is_null()) {
    throw InputError(file_, child_path, "missing required field");
  }
  return JsonNode(doc_, &*it, file_, child_path);
}

JsonNode JsonNode::operator[](size_t index) const {
  if (!node_->is_array()) Fail("expected an array");
  if (index >= node_->size()) Fail("index " + std::to_string(index) + " out of range");
  return JsonNode(doc_, &(*node_)[index], file_, path_ + "[" + std::to_string(index) + "]");
}

size_t JsonNode::Size() const {
  if (!node_->is_array()) Fail("expected an array");
  return node_->size();
}

std::vector<std::string> JsonNode::Keys() const {
  if (!node_->is_object()) Fail("expected an object");
  std::vector<std::string> keys;
  for (auto it = node_->begin(); it != node_->end(); ++it) keys.push_back(it.key());
  return keys;
}

double JsonNode::Number() const {
  if (!node_->is_number()) Fail("expected a number, got " + std::string(node_->type_name()));
  const double value = node_->get<double>();
  if (!std::isfinite(value)) Fail("expected a finite number");
  return value;
}

int JsonNode::Int() const {
  if (!node_->is_number_integer()) Fail("expected an integer, got " + node_->dump());
  return node_->get<int>();
}

bool JsonNode::Bool() const {
  if (!node_->is_boolean()) Fail("expected true or false, got " + node_->dump());
  return node_->get<bool>();
}

std::string JsonNode::String() const {
  if (!node_->is_string()) Fail("expected a string, got " + std::string(node_->type_name()));
  return node_->get<std::string>();
}

std::vector<double> JsonNode::Numbers() const {
  if (!node_->is_array()) Fail("expected an array of numbers");
  std::vector<double> values;
  for (size_t i = 0; i < node_->size(); ++i) values.push_back((*this)[i].Number());
  return values;
}

Eigen::Vector3d JsonNode::Vec3() const {
  const std::vector<double> v = Numbers();
  if (v.size() != 3) Fail("expected 3 numbers, got " + std::to_string(v.size()));
  return {v[0], v[1], v[2]};
}

Eigen::Vector2d JsonNode::Vec2() const {
  const std::vector<double> v = Numbers();
  if (v.size() != 2) Fail("expected 2 numbers, got " + std::to_string(v.size()));
  return {v[0], v[1]};
}

double JsonNode::GetDouble(const std::string& key, double fallback) const {
  return Has(key) ? (*this)[key].Number() : fallback;
}
int JsonNode::GetInt(const std::string& key, int fallback) const {
  return Has(key) ? (*this)[key].Int() : fallback;
}
bool JsonNode::GetBool(const std::string& key, bool fallback) const {
  return Has(key) ? (*this)[key].Bool() : fallback;
}
std::string JsonNode::GetString(const std::string& key, const std::string& fallback) const {
  return Has(key) ? (*this)[key].String() : fallback;
}

void JsonNode::CheckKeys(const std::vector<std::string>& allowed) const {
  for (const std::string& key : Keys()) {
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
      throw InputError(file_, path_.empty() ? key : path_ + "." + key, "unknown field");
    }
  }
}

JsonNode ParseJsonString(const std::string& text, const std::string& name) {
  auto doc = std::make_shared<nlohmann::json>();
  try {
    *doc = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    // Convert the byte offset into a line number for the message.
    size_t line = 1;
    for (size_t i = 0; i < std::min<size_t>(e.byte, text.size()); ++i) line += text[i] == '\n';
    std::string what = e.what();
    const size_t colon = what.rfind(": ");
    if (colon != std::string::npos) what = what.substr(colon + 2);
    throw InputError(name, "line " + std::to_string(line), "invalid JSON: " + what);
  }
  const nlohmann::json* root = doc.get();
  return JsonNode(std::move(doc), root, name, "");
}

JsonNode ParseJsonFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "", "cannot open file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return ParseJsonString(buffer.str(), path);
}

Eigen::VectorXd JsonNode::FiniteVector(int size) const {
  const std::vector<double> r = Numbers();
  if (r.size() != static_cast<size_t>(size)) Fail("must have " + std::to_string(size) + " values");
  Eigen::VectorXd v(size);
  for (int i = 0; i < size; ++i) {
    if (!std::isfinite(r[i])) Fail("values must be finite");
    v(i) = r[i];
  }
  return v;
}

Eigen::MatrixXd JsonNode::FiniteMatrix(int rows, int cols) const {
  if (Size() != static_cast<size_t>(rows)) Fail("must have " + std::to_string(rows) + " rows");
  Eigen::MatrixXd m(rows, cols);
  for (int i = 0; i < rows; ++i) m.row(i) = (*this)[i].FiniteVector(cols).transpose();
  return m;
}

}  // namespace irbench
