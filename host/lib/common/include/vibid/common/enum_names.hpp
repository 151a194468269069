// Names of enum values as files, tables and command lines spell them. One table per enum serves
// both ways, so each name is written once and a parser cannot drift from its printer.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "vibid/common/error.hpp"

namespace vibid {

template <typename Enum>
struct EnumName {
  Enum value;
  const char* name;
};

template <typename Enum, std::size_t N>
using EnumNames = std::array<EnumName<Enum>, N>;

/// The name of `value`, or `fallback` for a value the table lacks (a byte off the wire).
template <typename Enum, std::size_t N>
constexpr const char* NameOf(const EnumNames<Enum, N>& table, Enum value, const char* fallback) {
  for (const EnumName<Enum>& e : table) {
    if (e.value == value) return e.name;
  }
  return fallback;
}

/// The value named `name`, if the table has it.
template <typename Enum, std::size_t N>
constexpr std::optional<Enum> FindByName(const EnumNames<Enum, N>& table, std::string_view name) {
  for (const EnumName<Enum>& e : table) {
    if (name == e.name) return e.value;
  }
  return std::nullopt;
}

/// The names for a message: "a, b or c".
template <typename Enum, std::size_t N>
std::string NameList(const EnumNames<Enum, N>& table) {
  std::string out;
  for (std::size_t i = 0; i < N; ++i) {
    if (i > 0) out += i + 1 == N ? " or " : ", ";
    out += table[i].name;
  }
  return out;
}

/// The value named `name`; InputError "unknown WHAT 'NAME' (expected a, b or c)" otherwise.
template <typename Enum, std::size_t N>
Enum ParseName(const EnumNames<Enum, N>& table, std::string_view name, std::string_view what) {
  if (const std::optional<Enum> value = FindByName(table, name)) return *value;
  throw InputError("unknown " + std::string(what) + " '" + std::string(name) + "' (expected " +
                   NameList(table) + ")");
}

}  // namespace vibid
