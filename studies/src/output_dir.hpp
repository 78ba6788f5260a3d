#pragma once
// Output-folder handling of the studies (private to studies/).
#include <filesystem>
#include <string>

namespace abuopt::studies_detail {

// Whole or not at all (write_file_atomic); throws OutputError.
void write_text_file(const std::filesystem::path& path, const std::string& text);

// A table id as a folder name ("4.1" stays, anything but [A-Za-z0-9._-] becomes '_').
std::string table_dir_name(const std::string& id);

}  // namespace abuopt::studies_detail
