#include "mlidar/io/text_fields.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <system_error>
#include <type_traits>

#include "mlidar/core/error.hpp"

namespace mlidar::io {
namespace {

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; }

// Quotes a token for an error message, shortened so a binary blob stays readable.
std::string quoted(std::string_view token) {
  constexpr std::size_t kMaxShown = 40;
  std::string shown(token.substr(0, kMaxShown));
  for (char& c : shown) {
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
  }
  return "'" + shown + (token.size() > kMaxShown ? "...'" : "'");
}

// std::from_chars rejects a leading '+', which some writers emit.
std::string_view without_plus(std::string_view token) {
  return token.size() > 1 && token.front() == '+' && token[1] != '-' ? token.substr(1) : token;
}

}  // namespace

std::vector<NumberedLine> split_lines(std::string_view text) {
  std::vector<NumberedLine> lines;
  std::size_t start = 0;
  std::size_t number = 1;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(start, end - start);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    lines.push_back({number++, line});
    start = end + 1;
  }
  return lines;
}

std::vector<std::string_view> split_tokens(std::string_view line, char separator) {
  std::vector<std::string_view> tokens;
  std::size_t i = 0;
  const auto is_break = [separator](char c) { return is_space(c) || (separator != '\0' && c == separator); };
  while (i < line.size()) {
    while (i < line.size() && is_break(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !is_break(line[i])) ++i;
    if (i > start) tokens.push_back(line.substr(start, i - start));
  }
  return tokens;
}

std::string_view trim(std::string_view line) {
  while (!line.empty() && is_space(line.front())) line.remove_prefix(1);
  while (!line.empty() && is_space(line.back())) line.remove_suffix(1);
  return line;
}

std::string lowercase(std::string_view text) {
  std::string out(text);
  std::transform(out.begin(), out.end(), out.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

double parse_double(std::string_view token, const std::string& source, const std::string& field) {
  const std::string_view digits = without_plus(token);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (ec != std::errc() || end != digits.data() + digits.size() || digits.empty()) {
    throw InputError(source, field, "expected a number, found " + quoted(token));
  }
  return value;
}

double parse_finite(std::string_view token, const std::string& source, const std::string& field) {
  const double value = parse_double(token, source, field);
  if (!std::isfinite(value)) throw InputError(source, field, "expected a finite number, found " + quoted(token));
  return value;
}

long long parse_integer(std::string_view token, const std::string& source, const std::string& field) {
  const std::string_view digits = without_plus(token);
  long long value = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (ec != std::errc() || end != digits.data() + digits.size() || digits.empty()) {
    throw InputError(source, field, "expected an integer, found " + quoted(token));
  }
  return value;
}

std::string line_field(std::size_t number) { return "line " + std::to_string(number); }

std::string exact_number(double value) {
  std::array<char, 64> buffer{};
  const auto [end, ec] = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  return ec == std::errc() ? std::string(buffer.data(), end) : std::string("nan");
}

namespace {

template <typename T>
bool parse_exact(std::string_view word, T& value) {
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
  return ec == std::errc{} && end == word.data() + word.size();
}

// Floats too small for float32 round to zero or a subnormal instead of failing.
bool parse_float(std::string_view word, float& value) {
  if (parse_exact(word, value)) return true;
  double wide = 0.0;
  if (!parse_exact(word, wide) || std::abs(wide) >= std::numeric_limits<float>::min()) return false;
  value = static_cast<float>(wide);
  return true;
}

template <typename T>
bool parse_into(std::string_view word, std::byte* out) {
  if (word.size() > 1 && word[0] == '+' && word[1] != '-') word.remove_prefix(1);
  T value{};
  bool ok = false;
  if constexpr (std::is_same_v<T, float>) {
    ok = parse_float(word, value);
  } else {
    ok = parse_exact(word, value);
  }
  if (ok) std::memcpy(out, &value, sizeof(T));
  return ok;
}

}  // namespace

bool parse_scalar_token(std::string_view word, ScalarType type, std::byte* out) {
  switch (type) {
    case ScalarType::kI8:
      return parse_into<std::int8_t>(word, out);
    case ScalarType::kU8:
      return parse_into<std::uint8_t>(word, out);
    case ScalarType::kI16:
      return parse_into<std::int16_t>(word, out);
    case ScalarType::kU16:
      return parse_into<std::uint16_t>(word, out);
    case ScalarType::kI32:
      return parse_into<std::int32_t>(word, out);
    case ScalarType::kU32:
      return parse_into<std::uint32_t>(word, out);
    case ScalarType::kI64:
      return parse_into<std::int64_t>(word, out);
    case ScalarType::kU64:
      return parse_into<std::uint64_t>(word, out);
    case ScalarType::kF32:
      return parse_into<float>(word, out);
    case ScalarType::kF64:
      return parse_into<double>(word, out);
  }
  return false;
}

}  // namespace mlidar::io
