// SPDX-License-Identifier: BSD-3-Clause
#include "study/field_path.hpp"

#include <cctype>
#include <stdexcept>

namespace mcopt::study {

namespace {

bool isKeyCharacter(char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '-'; }

std::string prefix(const FieldPath& path, std::size_t steps) {
  std::string text;
  for (std::size_t k = 0; k < steps; ++k) {
    const FieldPathStep& step = path.steps[k];
    if (step.kind == FieldPathStep::Kind::Key) text += (text.empty() ? "" : ".") + step.key;
    else if (step.kind == FieldPathStep::Kind::Index) text += "[" + std::to_string(step.index) + "]";
    else text += "[" + step.key + "]";
  }
  return text;
}

}  // namespace

FieldPath parseFieldPath(const std::string& text) {
  FieldPath path;
  path.text = text;
  std::size_t i = 0;
  const auto fail = [&](const std::string& what) {
    throw std::invalid_argument("field path '" + text + "': " + what + " at character " + std::to_string(i + 1));
  };
  if (text.empty()) throw std::invalid_argument("empty field path");
  while (i < text.size()) {
    if (text[i] == '[') {
      const std::size_t close = text.find(']', i);
      if (close == std::string::npos) fail("'[' without ']'");
      const std::string inside = text.substr(i + 1, close - i - 1);
      if (inside.empty()) fail("empty []");
      FieldPathStep step;
      bool digits = true;
      for (char c : inside) digits = digits && std::isdigit(static_cast<unsigned char>(c)) != 0;
      if (digits) {
        step.kind = FieldPathStep::Kind::Index;
        step.index = std::stoul(inside);
      } else {
        step.kind = FieldPathStep::Kind::Name;
        step.key = inside;
      }
      if (path.steps.empty()) fail("a path starts with a field name");
      path.steps.push_back(step);
      i = close + 1;
      if (i < text.size() && text[i] != '.' && text[i] != '[') fail("expected '.' or '[' after ']'");
      if (i < text.size() && text[i] == '.') {
        ++i;
        if (i == text.size()) fail("a path ends with a field, not '.'");
      }
      continue;
    }
    const std::size_t start = i;
    while (i < text.size() && isKeyCharacter(text[i])) ++i;
    if (i == start) fail("expected a field name");
    path.steps.push_back({FieldPathStep::Kind::Key, text.substr(start, i - start), 0});
    if (i < text.size() && text[i] == '.') {
      ++i;
      if (i == text.size()) fail("a path ends with a field, not '.'");
    } else if (i < text.size() && text[i] != '[') {
      fail(std::string("unexpected '") + text[i] + "'");
    }
  }
  return path;
}

void setField(YAML::Node root, const FieldPath& path, const YAML::Node& value) {
  // yaml-cpp nodes are handles: assigning through `node` writes into `root`'s tree. Each step
  // is resolved on a fresh handle (reset), never by assigning one handle to another, which
  // would overwrite the first node's content.
  YAML::Node node;
  node.reset(root);
  for (std::size_t k = 0; k < path.steps.size(); ++k) {
    const FieldPathStep& step = path.steps[k];
    const bool last = k + 1 == path.steps.size();
    YAML::Node next;
    if (step.kind == FieldPathStep::Kind::Key) {
      if (node.IsDefined() && !node.IsMap() && !node.IsNull())
        throw std::invalid_argument("'" + prefix(path, k) + "' is not a mapping: it has no field '" + step.key + "'");
      if (last) {
        node[step.key] = YAML::Clone(value);
        return;
      }
      next.reset(node[step.key]);
    } else if (step.kind == FieldPathStep::Kind::Index) {
      if (!node.IsSequence())
        throw std::invalid_argument("'" + prefix(path, k) + "' is not a list" + (node.IsDefined() && !node.IsNull() ? "" : " (it is absent)"));
      if (step.index >= node.size())
        throw std::invalid_argument("'" + prefix(path, k) + "' has " + std::to_string(node.size()) + " elements: no [" +
                                    std::to_string(step.index) + "]");
      if (last) {
        node[step.index] = YAML::Clone(value);
        return;
      }
      next.reset(node[step.index]);
    } else {
      if (!node.IsSequence())
        throw std::invalid_argument("'" + prefix(path, k) + "' is not a list" + (node.IsDefined() && !node.IsNull() ? "" : " (it is absent)"));
      std::size_t found = node.size();
      for (std::size_t e = 0; e < node.size(); ++e)
        if (node[e].IsMap() && node[e]["name"] && node[e]["name"].IsScalar() && node[e]["name"].Scalar() == step.key) {
          found = e;
          break;
        }
      if (found == node.size())
        throw std::invalid_argument("'" + prefix(path, k) + "' has no element named '" + step.key + "'");
      if (last) {
        node[found] = YAML::Clone(value);
        return;
      }
      next.reset(node[found]);
    }
    node.reset(next);
  }
}

YAML::Node getField(const YAML::Node& root, const FieldPath& path) {
  YAML::Node node = YAML::Clone(root);
  for (std::size_t k = 0; k < path.steps.size(); ++k) {
    const FieldPathStep& step = path.steps[k];
    YAML::Node next;
    if (step.kind == FieldPathStep::Kind::Key) {
      if (!node.IsMap()) throw std::invalid_argument("'" + prefix(path, k) + "' is not a mapping: it has no field '" + step.key + "'");
      if (!node[step.key]) throw std::invalid_argument("'" + prefix(path, k + 1) + "' is not set");
      next.reset(node[step.key]);
    } else {
      if (!node.IsSequence()) throw std::invalid_argument("'" + prefix(path, k) + "' is not a list");
      std::size_t found = node.size();
      if (step.kind == FieldPathStep::Kind::Index) {
        found = step.index;
        if (found >= node.size())
          throw std::invalid_argument("'" + prefix(path, k) + "' has " + std::to_string(node.size()) + " elements: no [" +
                                      std::to_string(step.index) + "]");
      } else {
        for (std::size_t e = 0; e < node.size(); ++e)
          if (node[e].IsMap() && node[e]["name"] && node[e]["name"].IsScalar() && node[e]["name"].Scalar() == step.key) {
            found = e;
            break;
          }
        if (found == node.size()) throw std::invalid_argument("'" + prefix(path, k) + "' has no element named '" + step.key + "'");
      }
      next.reset(node[found]);
    }
    node.reset(next);
  }
  return node;
}

}  // namespace mcopt::study
