#pragma once
// Conversions between Python objects and what the C++ readers and results use.
#include <string>

#include <nlohmann/json.hpp>
#include <pybind11/pybind11.h>
#include <yaml-cpp/yaml.h>

#include "abuopt/common/yaml_reader.hpp"

namespace abuopt::python {

// A config given as a path (str or os.PathLike: the YAML file, read by YamlReader::load_file; a
// missing file raises FileNotFoundError) or
// as a dict (converted node by node into the YAML document the file would hold: mappings, lists,
// bool, int, float (shortest round-trip text), str, None). Either way the same C++ readers read
// it, so validation and messages are those of the command line.
YamlReader load_config(const pybind11::handle& config);

// A Python value as a YAML node (see load_config); TypeError for other types, naming `path`.
YAML::Node to_yaml(const pybind11::handle& value, const std::string& path);

// A JSON value as plain Python objects (dict, list, float, int, bool, str, None).
pybind11::object to_python(const nlohmann::json& j);

}  // namespace abuopt::python
