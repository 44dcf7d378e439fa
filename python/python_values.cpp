// SPDX-License-Identifier: BSD-3-Clause
#include <pybind11/stl.h>

#include <cmath>

#include "python/bindings.hpp"

namespace mcopt::python {

namespace {

template <class Json>
py::object convert(const Json& value) {
  if (value.is_null()) return py::none();
  if (value.is_boolean()) return py::bool_(value.template get<bool>());
  if (value.is_number_integer()) return py::int_(value.template get<long long>());
  if (value.is_number()) return py::float_(value.template get<double>());
  if (value.is_string()) return py::str(value.template get<std::string>());
  if (value.is_object()) {
    py::dict out;
    for (auto it = value.begin(); it != value.end(); ++it) out[py::str(it.key())] = convert(it.value());
    return out;
  }
  // A list: numbers become an array, equally long lists of numbers a matrix.
  const auto numbers = [](const Json& list) {
    if (list.empty()) return false;
    for (const auto& e : list)
      if (!e.is_number()) return false;
    return true;
  };
  if (numbers(value)) {
    bool integers = true;
    for (const auto& e : value) integers = integers && e.is_number_integer();
    if (integers) {
      py::array_t<long long> out(static_cast<py::ssize_t>(value.size()));
      auto a = out.mutable_unchecked<1>();
      for (std::size_t i = 0; i < value.size(); ++i) a(static_cast<py::ssize_t>(i)) = value[i].template get<long long>();
      return out;
    }
    py::array_t<double> out(static_cast<py::ssize_t>(value.size()));
    auto a = out.mutable_unchecked<1>();
    for (std::size_t i = 0; i < value.size(); ++i) a(static_cast<py::ssize_t>(i)) = value[i].template get<double>();
    return out;
  }
  bool matrix = !value.empty();
  for (const auto& row : value) matrix = matrix && row.is_array() && numbers(row) && row.size() == value[0].size();
  if (matrix) {
    const auto rows = static_cast<py::ssize_t>(value.size()), cols = static_cast<py::ssize_t>(value[0].size());
    py::array_t<double> out({rows, cols});
    auto a = out.mutable_unchecked<2>();
    for (py::ssize_t r = 0; r < rows; ++r)
      for (py::ssize_t c = 0; c < cols; ++c)
        a(r, c) = value[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)].template get<double>();
    return out;
  }
  py::list out;
  for (const auto& e : value) out.append(convert(e));
  return out;
}

std::string shapeText(const py::array& a) {
  std::string text = "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) text += (d ? ", " : "") + std::to_string(a.shape(d));
  return text + (a.ndim() == 1 ? ",)" : ")");
}

}  // namespace

std::mutex& ipoptMutex() {
  static std::mutex mutex;
  return mutex;
}

py::object toPython(const nlohmann::json& value) { return convert(value); }
py::object toPython(const nlohmann::ordered_json& value) { return convert(value); }

py::array_t<double, py::array::c_style> numericArray(const py::handle& value, const std::string& name) {
  const py::module_ numpy = py::module_::import("numpy");
  py::array raw;
  try {
    raw = numpy.attr("asarray")(value);
  } catch (const py::error_already_set&) {
    throw py::value_error(name + ": expected numbers (an array or a list)");
  }
  const char kind = raw.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u')
    throw py::value_error(name + ": expected numbers, got an array of " + std::string(py::str(raw.dtype())));
  auto out = py::array_t<double, py::array::c_style>::ensure(raw);
  if (!out) throw py::value_error(name + ": expected numbers");
  const double* data = out.data();
  for (py::ssize_t i = 0; i < out.size(); ++i)
    if (!std::isfinite(data[i])) throw py::value_error(name + ": not a finite number at flat index " + std::to_string(i));
  return out;
}

Eigen::VectorXd vectorArgument(const py::handle& value, const std::string& name, Eigen::Index size) {
  const auto a = numericArray(value, name);
  if (a.ndim() != 1 || a.shape(0) != size)
    throw py::value_error(name + ": expected an array of shape (" + std::to_string(size) + ",), got " + shapeText(a));
  return Eigen::Map<const Eigen::VectorXd>(a.data(), size);
}

Eigen::MatrixXd matrixArgument(const py::handle& value, const std::string& name, Eigen::Index rows, Eigen::Index cols) {
  const auto a = numericArray(value, name);
  const bool fits = a.ndim() == 2 && (rows < 0 || a.shape(0) == rows) && (cols < 0 || a.shape(1) == cols);
  if (!fits)
    throw py::value_error(name + ": expected an array of shape (" + (rows < 0 ? std::string("any") : std::to_string(rows)) +
                          ", " + (cols < 0 ? std::string("any") : std::to_string(cols)) + "), got " + shapeText(a));
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  return Eigen::Map<const RowMajor>(a.data(), a.shape(0), a.shape(1));
}

Eigen::MatrixXd statesArgument(const py::handle& value, const std::string& name, Eigen::Index n, bool& batch) {
  const auto a = numericArray(value, name);
  if (a.ndim() == 1 && a.shape(0) == n) {
    batch = false;
    return Eigen::Map<const Eigen::VectorXd>(a.data(), n).transpose();
  }
  if (a.ndim() == 2 && a.shape(1) == n) {
    batch = true;
    using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
    return Eigen::Map<const RowMajor>(a.data(), a.shape(0), n);
  }
  throw py::value_error(name + ": expected an array of shape (" + std::to_string(n) + ",) or (N, " + std::to_string(n) +
                        "), got " + shapeText(a));
}

py::array_t<double> matrixToNumpy(const Eigen::Ref<const Eigen::MatrixXd>& m) {
  py::array_t<double> out({static_cast<py::ssize_t>(m.rows()), static_cast<py::ssize_t>(m.cols())});
  auto a = out.mutable_unchecked<2>();
  for (Eigen::Index r = 0; r < m.rows(); ++r)
    for (Eigen::Index c = 0; c < m.cols(); ++c) a(r, c) = m(r, c);
  return out;
}

py::array_t<double> vectorToNumpy(const Eigen::Ref<const Eigen::VectorXd>& v) {
  py::array_t<double> out(static_cast<py::ssize_t>(v.size()));
  auto a = out.mutable_unchecked<1>();
  for (Eigen::Index i = 0; i < v.size(); ++i) a(i) = v[i];
  return out;
}

}  // namespace mcopt::python
