// SPDX-License-Identifier: BSD-3-Clause
// The debug preset's MCOPT_CHECK_MALLOC arms Eigen's no-malloc check (core/no_malloc_scope.hpp):
// compiled only in builds with MCOPT_CHECK_MALLOC (tests/CMakeLists.txt), where it can fail.
#include <catch2/catch.hpp>

#include "core/no_malloc_scope.hpp"

using namespace mcopt;

TEST_CASE("a no-malloc scope forbids Eigen allocations while it lives, nested or not, and an unarmed one does not",
          "[core][allocation]") {
  using Eigen::internal::is_malloc_allowed;
  REQUIRE(is_malloc_allowed());
  {
    const NoMallocScope outer("test, outer");
    CHECK_FALSE(is_malloc_allowed());
    {
      const NoMallocScope inner("test, inner");
      CHECK_FALSE(is_malloc_allowed());
    }
    CHECK_FALSE(is_malloc_allowed());  // the outer scope still holds
  }
  CHECK(is_malloc_allowed());
  {
    const NoMallocScope unarmed("test, unarmed", false);
    CHECK(is_malloc_allowed());
  }
  CHECK(is_malloc_allowed());
}
