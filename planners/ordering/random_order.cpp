#include "planners/ordering/random_order.hpp"

#include <random>
#include <utility>

namespace depotwin {

namespace {

// uniform integer in [0, bound) by rejection, from explicit mt19937_64 arithmetic (the
// same sequence with every standard library)
std::uint64_t below(std::mt19937_64& rng, std::uint64_t bound) {
  const std::uint64_t limit = ~std::uint64_t{0} - (~std::uint64_t{0} % bound);
  for (;;) {
    const std::uint64_t x = rng();
    if (x < limit) return x % bound;
  }
}

}  // namespace

OrderResult random_order(int path_count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  OrderResult result;
  for (int i = 0; i < path_count; ++i) result.order.push_back(i);
  // Fisher-Yates shuffle, then one coin per path for its direction
  for (int i = path_count - 1; i > 0; --i)
    std::swap(result.order[i], result.order[below(rng, static_cast<std::uint64_t>(i) + 1)]);
  for (int i = 0; i < path_count; ++i) result.reversed.push_back((rng() >> 63) != 0);
  return result;
}

}  // namespace depotwin
