#include "output_dir.hpp"

#include <cctype>

#include "abuopt/common/output_file.hpp"

namespace abuopt::studies_detail {

namespace fs = std::filesystem;

void write_text_file(const fs::path& path, const std::string& text) { write_file_atomic(path, text); }

std::string table_dir_name(const std::string& id) {
  std::string s = id;
  for (char& ch : s)
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '.' || ch == '_' || ch == '-')) ch = '_';
  return s;
}

}  // namespace abuopt::studies_detail
