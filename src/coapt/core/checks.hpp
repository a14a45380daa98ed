#pragma once
/// @file checks.hpp
/// Checks of physical parameters that are not read through a case file's Section (which has
/// its own range checks): each throws InputError as "<where>.<name> = <value> [<unit>] must ...".

#include <string_view>

namespace coapt {

/// Throws InputError unless `value` is finite.
void require_finite(std::string_view where, std::string_view name, double value,
                    std::string_view unit);
/// Throws InputError unless `value` is finite and > 0.
void require_positive(std::string_view where, std::string_view name, double value,
                      std::string_view unit);
/// Throws InputError unless `value` is finite and >= 0.
void require_non_negative(std::string_view where, std::string_view name, double value,
                          std::string_view unit);

}  // namespace coapt
