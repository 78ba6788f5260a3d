#include "convert.hpp"

#include <Python.h>

#include <cstdio>

namespace py = pybind11;

namespace abuopt::python {

namespace {

std::string float_text(double v) {
  // repr() of a Python float is the shortest text that reads back to the same double.
  return py::repr(py::float_(v)).cast<std::string>();
}

}  // namespace

YAML::Node to_yaml(const py::handle& value, const std::string& path) {
  if (value.is_none()) return YAML::Node(YAML::NodeType::Null);
  if (py::isinstance<py::bool_>(value)) return YAML::Node(value.cast<bool>() ? "true" : "false");
  if (py::isinstance<py::str>(value)) return YAML::Node(value.cast<std::string>());
  if (py::isinstance<py::dict>(value)) {
    YAML::Node n(YAML::NodeType::Map);
    for (const auto& [k, v] : value.cast<py::dict>()) {
      if (!py::isinstance<py::str>(k))
        throw py::type_error("config key " + py::repr(k).cast<std::string>() + (path.empty() ? "" : " in " + path) +
                             ": keys must be strings");
      const std::string key = k.cast<std::string>();
      n[key] = to_yaml(v, path.empty() ? key : path + "." + key);
    }
    return n;
  }
  if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
    YAML::Node n(YAML::NodeType::Sequence);
    std::size_t i = 0;
    for (const auto& v : value) {
      n.push_back(to_yaml(v, path + "[" + std::to_string(i) + "]"));
      ++i;
    }
    return n;
  }
  // Integers (also NumPy's) before floats: an int stays an int in the YAML text.
  if (PyIndex_Check(value.ptr())) return YAML::Node(py::str(py::int_(py::reinterpret_borrow<py::object>(value))).cast<std::string>());
  if (py::isinstance<py::float_>(value) || PyNumber_Check(value.ptr())) {
    PyObject* f = PyNumber_Float(value.ptr());
    if (f) {
      const double v = PyFloat_AsDouble(f);
      Py_DECREF(f);
      return YAML::Node(float_text(v));
    }
    PyErr_Clear();
  }
  if (py::hasattr(value, "tolist")) return to_yaml(value.attr("tolist")(), path);  // NumPy arrays
  throw py::type_error("config value " + (path.empty() ? std::string("<root>") : path) + " = " +
                       py::repr(value).cast<std::string>() +
                       ": must be a dict, list, str, int, float, bool or None (YAML values)");
}

YamlReader load_config(const py::handle& config) {
  if (py::isinstance<py::dict>(config)) return YamlReader(to_yaml(config, ""), "");
  py::object os = py::module_::import("os");
  if (py::isinstance<py::str>(config) || py::hasattr(config, "__fspath__")) {
    const std::string path = os.attr("fspath")(config).cast<std::string>();
    // A missing file is Python's FileNotFoundError (an OSError, as open() raises), not a ConfigError.
    if (!os.attr("path").attr("exists")(path).cast<bool>()) {
      PyErr_SetObject(PyExc_FileNotFoundError,
                      py::make_tuple(2, "No such config file", path).ptr());  // errno ENOENT, strerror, filename
      throw py::error_already_set();
    }
    return YamlReader::load_file(path);
  }
  throw py::type_error("config must be a YAML file path (str or os.PathLike) or a dict, not " +
                       py::str(py::type::handle_of(config).attr("__name__")).cast<std::string>());
}

py::object to_python(const nlohmann::json& j) {
  switch (j.type()) {
    case nlohmann::json::value_t::null: return py::none();
    case nlohmann::json::value_t::boolean: return py::bool_(j.get<bool>());
    case nlohmann::json::value_t::number_integer: return py::int_(j.get<long long>());
    case nlohmann::json::value_t::number_unsigned: return py::int_(j.get<unsigned long long>());
    case nlohmann::json::value_t::number_float: return py::float_(j.get<double>());
    case nlohmann::json::value_t::string: return py::str(j.get<std::string>());
    case nlohmann::json::value_t::array: {
      py::list l;
      for (const auto& e : j) l.append(to_python(e));
      return l;
    }
    case nlohmann::json::value_t::object: {
      py::dict d;
      for (const auto& [k, v] : j.items()) d[py::str(k)] = to_python(v);
      return d;
    }
    default: return py::none();
  }
}

}  // namespace abuopt::python
