#include "output_dir.hpp"

#include <cctype>
#include <fstream>

#include "abuopt/common/config_error.hpp"

namespace abuopt::studies_detail {

namespace fs = std::filesystem;

void write_text_file(const fs::path& path, const std::string& text) {
  std::ofstream f(path);
  if (!f) throw ConfigError("output file", path.string(), "cannot be written");
  f << text;
}

std::string table_dir_name(const std::string& id) {
  std::string s = id;
  for (char& ch : s)
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '.' || ch == '_' || ch == '-')) ch = '_';
  return s;
}

}  // namespace abuopt::studies_detail
