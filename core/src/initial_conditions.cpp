#include "abuopt/core/initial_conditions.hpp"

#include <array>
#include <cmath>
#include <stdexcept>
#include <numeric>
#include <random>

#include "abuopt/common/config_error.hpp"

namespace abuopt {

namespace {

constexpr double kTwoPi = 6.283185307179586476925286766559;

// Stream tags: keep the streams of different uses of one seed unrelated.
constexpr std::uint64_t kTagRandom = 0x52414e444f4d5054ULL;  // "RANDOMPT"
constexpr std::uint64_t kTagLhs = 0x4c48535045524d53ULL;     // "LHSPERMS"
constexpr std::uint64_t kTagShift = 0x514d4353484946ULL;     // "QMCSHIF"

// Wraps a value that should be in [0, 2 pi) but may round up to 2 pi.
double to_angle(double unit) {
  double a = kTwoPi * unit;
  return a < kTwoPi ? a : 0.0;
}

// Uniform integer in [0, n) by rejection (portable, unbiased).
std::uint64_t bounded(std::mt19937_64& rng, std::uint64_t n) {
  const std::uint64_t threshold = (std::uint64_t{0} - n) % n;  // 2^64 mod n
  std::uint64_t x;
  do {
    x = rng();
  } while (x < threshold);
  return x % n;
}

std::uint64_t prime(std::size_t j) {
  // j-th prime (0-based), by trial division: N is small.
  std::uint64_t p = 1;
  std::size_t found = 0;
  while (true) {
    ++p;
    bool is_prime = true;
    for (std::uint64_t q = 2; q * q <= p; ++q)
      if (p % q == 0) {
        is_prime = false;
        break;
      }
    if (is_prime && found++ == j) return p;
  }
}

double radical_inverse(std::uint64_t i, std::uint64_t base) {
  double inv = 1.0 / static_cast<double>(base), f = inv, r = 0.0;
  while (i > 0) {
    r += f * static_cast<double>(i % base);
    i /= base;
    f *= inv;
  }
  return r;
}

// Sobol' direction numbers: Joe & Kuo, new-joe-kuo-6.21201, dimensions 2..10 (dimension 1 is the
// van der Corput sequence in base 2). Per dimension: degree s, polynomial coefficients a, m_1..m_s.
struct SobolPoly {
  unsigned s;
  unsigned a;
  std::array<std::uint32_t, 5> m;
};
constexpr std::array<SobolPoly, kSobolMaxDimension - 1> kSobolPolys{{
    {1, 0, {1, 0, 0, 0, 0}},
    {2, 1, {1, 3, 0, 0, 0}},
    {3, 1, {1, 3, 1, 0, 0}},
    {3, 2, {1, 1, 1, 0, 0}},
    {4, 1, {1, 1, 3, 3, 0}},
    {4, 4, {1, 3, 5, 13, 0}},
    {5, 2, {1, 1, 5, 5, 17}},
    {5, 4, {1, 1, 5, 5, 5}},
    {5, 7, {1, 1, 7, 11, 19}},
}};

constexpr unsigned kSobolBits = 32;

// Direction numbers V[1..32] (index 0 unused) of dimension j (0-based), scaled by 2^32.
std::array<std::uint32_t, kSobolBits + 1> sobol_directions(std::size_t j) {
  std::array<std::uint32_t, kSobolBits + 1> v{};
  if (j == 0) {
    for (unsigned i = 1; i <= kSobolBits; ++i) v[i] = std::uint32_t{1} << (kSobolBits - i);
    return v;
  }
  const SobolPoly& p = kSobolPolys[j - 1];
  for (unsigned i = 1; i <= p.s; ++i) v[i] = p.m[i - 1] << (kSobolBits - i);
  for (unsigned i = p.s + 1; i <= kSobolBits; ++i) {
    v[i] = v[i - p.s] ^ (v[i - p.s] >> p.s);
    for (unsigned k = 1; k < p.s; ++k) v[i] ^= ((p.a >> (p.s - 1 - k)) & 1u) * v[i - k];
  }
  return v;
}

double sobol_coordinate(std::uint64_t index, const std::array<std::uint32_t, kSobolBits + 1>& v) {
  const std::uint64_t gray = index ^ (index >> 1);
  std::uint32_t x = 0;
  for (unsigned bit = 0; bit < kSobolBits; ++bit)
    if ((gray >> bit) & 1u) x ^= v[bit + 1];
  return static_cast<double>(x) / 4294967296.0;  // 2^32
}

std::vector<double> shift_vector(const InitialConditionDesign& d) {
  std::vector<double> s(d.balls, 0.0);
  if (!d.random_shift) return s;
  for (std::size_t j = 0; j < d.balls; ++j) s[j] = unit_double(hash_seed(d.seed, kTagShift, j));
  return s;
}

double wrap_unit(double u) {
  u -= std::floor(u);
  return u < 1.0 ? u : 0.0;
}

// Latin hypercube: per axis a permutation of the strata and a jitter per point.
std::vector<std::vector<double>> latin_hypercube(const InitialConditionDesign& d) {
  const std::size_t n = d.count;
  std::vector<std::vector<double>> pts(n, std::vector<double>(d.balls));
  for (std::size_t j = 0; j < d.balls; ++j) {
    std::mt19937_64 rng(hash_seed(d.seed, kTagLhs, j));
    std::vector<std::size_t> perm(n);
    std::iota(perm.begin(), perm.end(), std::size_t{0});
    for (std::size_t i = n; i > 1; --i) std::swap(perm[i - 1], perm[bounded(rng, i)]);
    for (std::size_t i = 0; i < n; ++i) {
      const double u = (static_cast<double>(perm[i]) + unit_double(rng())) / static_cast<double>(n);
      pts[i][j] = to_angle(u);
    }
  }
  return pts;
}

}  // namespace

std::vector<double> sobol_unit_point(std::uint64_t index, std::size_t dims) {
  if (dims < 1 || dims > kSobolMaxDimension)
    throw std::invalid_argument("sobol_unit_point: dims = " + std::to_string(dims) + ": must be in 1.." +
                                std::to_string(kSobolMaxDimension));
  std::vector<double> u(dims);
  for (std::size_t j = 0; j < dims; ++j) u[j] = sobol_coordinate(index, sobol_directions(j));
  return u;
}

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

std::uint64_t hash_seed(std::uint64_t seed, std::uint64_t a, std::uint64_t b) {
  return splitmix64(splitmix64(splitmix64(seed) ^ a) ^ b);
}

double unit_double(std::uint64_t x) { return static_cast<double>(x >> 11) * 0x1.0p-53; }

std::string to_string(InitialConditionKind k) {
  switch (k) {
    case InitialConditionKind::Grid: return "grid";
    case InitialConditionKind::Random: return "random";
    case InitialConditionKind::LatinHypercube: return "lhs";
    case InitialConditionKind::Halton: return "halton";
    case InitialConditionKind::Sobol: return "sobol";
  }
  return "?";
}

InitialConditionKind initial_condition_kind_from_string(const std::string& text, const std::string& path) {
  for (auto k : {InitialConditionKind::Grid, InitialConditionKind::Random, InitialConditionKind::LatinHypercube,
                 InitialConditionKind::Halton, InitialConditionKind::Sobol})
    if (to_string(k) == text) return k;
  throw ConfigError(path, text, "must be one of: grid, random, lhs, halton, sobol");
}

std::size_t InitialConditionDesign::size() const {
  if (kind != InitialConditionKind::Grid) return count;
  std::size_t s = 1;
  for (std::size_t j = 0; j < balls; ++j) {
    if (grid_points_per_axis != 0 && s > kMaxDesignPoints / grid_points_per_axis) return kMaxDesignPoints + 1;
    s *= grid_points_per_axis;
  }
  return s;
}

void validate(const InitialConditionDesign& d, const std::string& path) {
  const std::string p = path.empty() ? "" : path + ".";
  if (d.balls < 1) throw ConfigError(p + "balls", std::to_string(d.balls), "must be >= 1 (the ABU has no balls)");
  if (d.kind == InitialConditionKind::Grid) {
    if (d.grid_points_per_axis < 1)
      throw ConfigError(p + "grid", std::to_string(d.grid_points_per_axis), "must be >= 1");
    if (d.size() > kMaxDesignPoints)
      throw ConfigError(p + "grid", std::to_string(d.grid_points_per_axis),
                        "grid^balls (balls = " + std::to_string(d.balls) + ") must be <= 2^32 points");
    return;
  }
  if (d.count < 1) throw ConfigError(p + "runs", std::to_string(d.count), "must be >= 1");
  if (d.count > kMaxDesignPoints) throw ConfigError(p + "runs", std::to_string(d.count), "must be <= 2^32");
  if (d.kind == InitialConditionKind::Sobol && d.balls > kSobolMaxDimension)
    throw ConfigError(p + "design", "sobol",
                      "supports at most " + std::to_string(kSobolMaxDimension) + " balls (the ABU has " +
                          std::to_string(d.balls) + "); use halton, lhs or random");
}

std::vector<double> initial_condition_at(const InitialConditionDesign& d, std::size_t index) {
  validate(d);
  if (index >= d.size())
    throw ConfigError("initial condition index", std::to_string(index),
                      "must be < the design size " + std::to_string(d.size()));
  std::vector<double> beta(d.balls);
  switch (d.kind) {
    case InitialConditionKind::Grid: {
      std::size_t rest = index;
      const std::size_t n = d.grid_points_per_axis;
      for (std::size_t j = d.balls; j-- > 0;) {
        const std::size_t k = rest % n;
        rest /= n;
        beta[j] = kTwoPi * static_cast<double>(k) / static_cast<double>(n);
      }
      break;
    }
    case InitialConditionKind::Random: {
      std::mt19937_64 rng(hash_seed(d.seed, kTagRandom, index));
      for (auto& b : beta) b = to_angle(unit_double(rng()));
      break;
    }
    case InitialConditionKind::LatinHypercube:
      return latin_hypercube(d)[index];
    case InitialConditionKind::Halton: {
      const auto s = shift_vector(d);
      for (std::size_t j = 0; j < d.balls; ++j) beta[j] = to_angle(wrap_unit(radical_inverse(index, prime(j)) + s[j]));
      break;
    }
    case InitialConditionKind::Sobol: {
      const auto s = shift_vector(d);
      for (std::size_t j = 0; j < d.balls; ++j)
        beta[j] = to_angle(wrap_unit(sobol_coordinate(index, sobol_directions(j)) + s[j]));
      break;
    }
  }
  return beta;
}

std::vector<std::vector<double>> generate_initial_conditions(const InitialConditionDesign& d) {
  validate(d);
  if (d.kind == InitialConditionKind::LatinHypercube) return latin_hypercube(d);
  const std::size_t n = d.size();
  std::vector<std::vector<double>> pts;
  pts.reserve(n);
  if (d.kind == InitialConditionKind::Sobol) {
    // Precompute the direction numbers once.
    std::vector<std::array<std::uint32_t, kSobolBits + 1>> dirs;
    for (std::size_t j = 0; j < d.balls; ++j) dirs.push_back(sobol_directions(j));
    const auto s = shift_vector(d);
    for (std::size_t i = 0; i < n; ++i) {
      std::vector<double> beta(d.balls);
      for (std::size_t j = 0; j < d.balls; ++j) beta[j] = to_angle(wrap_unit(sobol_coordinate(i, dirs[j]) + s[j]));
      pts.push_back(std::move(beta));
    }
    return pts;
  }
  for (std::size_t i = 0; i < n; ++i) pts.push_back(initial_condition_at(d, i));
  return pts;
}

}  // namespace abuopt
