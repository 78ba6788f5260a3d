#pragma once
// Shared by the surrogate tests: the message of the std::invalid_argument thrown by `f`
// ("" if it throws none), so a test can assert the exact text of a usage error.
#include <stdexcept>
#include <string>

namespace abuopt::surrogate::test {

template <class F>
std::string invalid_argument_message(F f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

}  // namespace abuopt::surrogate::test
