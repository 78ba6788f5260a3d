#pragma once
// Numbers typed by a user (command-line option values, the items of a list option such as
// --beta0 A,B or --scan FROM:TO:STEP): one reader, so that every option accepts and refuses the
// same texts, and says why.
//  * strtod: a subnormal value (4.9e-324) is a number, leading/trailing blanks are allowed, the
//    rest of the item must be used ("1x" is not a number);
//  * nan, inf (in any spelling, also nan(0x1)) and overflow (1e400) are refused: a value is finite.
// Every refusal is one ConfigError naming the option, its whole text and the rule.
#include <string>
#include <vector>

namespace abuopt {

// `item` as a finite double. key: the option ("--beta0"); whole: the option's whole text; rule:
// what the value must be (used in the message).
double parse_finite_number(const std::string& item, const std::string& key, const std::string& whole,
                           const std::string& rule);

// `text` split at `sep` (an empty item, e.g. "1,,2" or a trailing separator, is an error), each item
// by parse_finite_number.
std::vector<double> parse_number_list(const std::string& text, char sep, const std::string& key,
                                      const std::string& rule);

// `text` as a whole number in [lo, hi] (base 10); out of range says the range.
long long parse_integer(const std::string& text, const std::string& key, long long lo, long long hi);

}  // namespace abuopt
