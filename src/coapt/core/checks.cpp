#include "coapt/core/checks.hpp"

#include <fmt/format.h>

#include <cmath>

#include "coapt/core/error.hpp"

namespace coapt {

void require_finite(std::string_view where, std::string_view name, double value,
                    std::string_view unit) {
  if (!std::isfinite(value))
    throw InputError(
        fmt::format("{}.{} = {} [{}] must be a finite number", where, name, value, unit));
}

void require_positive(std::string_view where, std::string_view name, double value,
                      std::string_view unit) {
  require_finite(where, name, value, unit);
  if (!(value > 0.0))
    throw InputError(fmt::format("{}.{} = {} [{}] must be positive", where, name, value, unit));
}

void require_non_negative(std::string_view where, std::string_view name, double value,
                          std::string_view unit) {
  require_finite(where, name, value, unit);
  if (!(value >= 0.0))
    throw InputError(fmt::format("{}.{} = {} [{}] must not be negative", where, name, value, unit));
}

}  // namespace coapt
