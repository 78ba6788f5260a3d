#include "abuopt/core/parameters.hpp"

#include "abuopt/core/simulation_config.hpp"

namespace abuopt {

std::string to_string(BallContact c) { return c == BallContact::Hard ? "hard" : "none"; }

// The rules of every field and the ball-fits-its-track rule, from the one field list.
void validate(const AbuParameters& p, const char* path) { validate_fields(p, path); }

}  // namespace abuopt
