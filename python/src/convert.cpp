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

namespace {

// The walk of to_yaml, bounded as the YAML reader bounds a file (kMaxConfigNodes values,
// kMaxConfigDepth levels): a dict that contains itself, or lists that share lists exponentially,
// would otherwise recurse until the interpreter dies or run out of memory.
struct Walk {
  double nodes = 0;
};

YAML::Node to_yaml_bounded(const py::handle& value, const std::string& path, std::size_t depth, Walk& walk);

}  // namespace

YAML::Node to_yaml(const py::handle& value, const std::string& path) {
  Walk walk;
  return to_yaml_bounded(value, path, 0, walk);
}

namespace {

YAML::Node to_yaml_bounded(const py::handle& value, const std::string& path, std::size_t depth, Walk& walk) {
  const std::string where = path.empty() ? std::string("<root>") : path;
  if (depth > kMaxConfigDepth)
    throw ConfigError(where, "<nested value>",
                      "the config nests more than " + std::to_string(kMaxConfigDepth) +
                          " levels deep (does a dict or list contain itself?)");
  if (++walk.nodes > kMaxConfigNodes)
    throw ConfigError(where, "<value>",
                      "the config has more than 1e6 values (the limit of a config; lists or dicts shared many "
                      "times over count each time)");
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
      n[key] = to_yaml_bounded(v, path.empty() ? key : path + "." + key, depth + 1, walk);
    }
    return n;
  }
  if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
    YAML::Node n(YAML::NodeType::Sequence);
    std::size_t i = 0;
    for (const auto& v : value) {
      n.push_back(to_yaml_bounded(v, path + "[" + std::to_string(i) + "]", depth + 1, walk));
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
  if (py::hasattr(value, "tolist")) return to_yaml_bounded(value.attr("tolist")(), path, depth + 1, walk);  // NumPy arrays
  throw py::type_error("config value " + (path.empty() ? std::string("<root>") : path) + " = " +
                       py::repr(value).cast<std::string>() +
                       ": must be a dict, list, str, int, float, bool or None (YAML values)");
}

}  // namespace

YamlReader load_config(const py::handle& config) {
  if (py::isinstance<py::dict>(config)) return YamlReader(to_yaml(config, ""), "");
  py::object os = py::module_::import("os");
  if (py::isinstance<py::str>(config) || py::hasattr(config, "__fspath__")) {
    // the whole name, NULs included: load_file refuses a name with a NUL (it is not cut there)
    const std::string path = os.attr("fspath")(config).cast<std::string>();
    if (path.find('\0') != std::string::npos) return YamlReader::load_file(path);
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
