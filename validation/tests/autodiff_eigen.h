// Boost.Math forward-mode autodiff (boost/math/differentiation/autodiff.hpp) as an Eigen scalar, so that a
// kernel written for Vec3<T> can be instantiated on T = fvar and differentiated as is (no copy of its formula).
//
// Eigen needs NumTraits for a custom scalar (Eigen's "Using custom scalar types" page). Boost specialises
// std::numeric_limits for fvar (as its root type's), which GenericNumTraits reads for epsilon, digits, etc.;
// we add what GenericNumTraits cannot know: that fvar needs initialisation (a class type) and its operation
// costs (a first-order fvar carries two numbers). The elementary functions (sqrt, abs, ...) resolve by
// argument-dependent lookup in Boost's namespace, which is how Eigen's numext calls them.
#pragma once

#include <boost/math/differentiation/autodiff.hpp>

#include <Eigen/Core>

namespace Eigen {

template <typename RealType, std::size_t Order>
struct NumTraits<boost::math::differentiation::detail::fvar<RealType, Order>>
    : GenericNumTraits<boost::math::differentiation::detail::fvar<RealType, Order>> {
  using Self = boost::math::differentiation::detail::fvar<RealType, Order>;
  using Real = Self;
  using NonInteger = Self;
  using Nested = Self;
  using Literal = Self;
  enum {
    IsComplex = 0,
    IsInteger = 0,
    IsSigned = 1,
    RequireInitialization = 1,
    ReadCost = int(Order + 1) * NumTraits<RealType>::ReadCost,
    AddCost = int(Order + 1) * NumTraits<RealType>::AddCost,
    MulCost = int((Order + 1) * (Order + 2) / 2) * NumTraits<RealType>::MulCost,
  };
  static Self dummy_precision() { return Self(NumTraits<RealType>::dummy_precision()); }
};

}  // namespace Eigen
