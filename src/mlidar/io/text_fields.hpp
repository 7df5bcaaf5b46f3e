#pragma once
// Small helpers shared by the text formats (KITTI, TUM, OpenCalib, ascii PCD/PLY): lines with
// their numbers, whitespace tokens, strict number parsing with errors that
// name the file and the line, and exact (shortest round-trip) number printing.
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "mlidar/io/point_table.hpp"

namespace mlidar::io {

struct NumberedLine {
  std::size_t number = 0;  ///< 1-based
  std::string_view text;   ///< without the line break ('\r' stripped)
};

/// Splits text into lines (LF or CRLF); the views point into `text`.
std::vector<NumberedLine> split_lines(std::string_view text);
/// Tokens separated by spaces, tabs or `separator` (0: whitespace only).
std::vector<std::string_view> split_tokens(std::string_view line, char separator = '\0');
/// `line` without leading and trailing whitespace.
std::string_view trim(std::string_view line);
/// `text` with ASCII letters in lower case (file extensions, class names).
std::string lowercase(std::string_view text);

/// Parses the whole token as a double (InputError naming source and field otherwise).
double parse_double(std::string_view token, const std::string& source, const std::string& field);
/// As parse_double, and rejects NaN and infinities.
double parse_finite(std::string_view token, const std::string& source, const std::string& field);
/// Parses the whole token as a base-10 integer.
long long parse_integer(std::string_view token, const std::string& source, const std::string& field);

/// Parses the whole token as one scalar of `type` into `out` (scalar_size(type)
/// bytes, host order). Integers must be exact and fit the type; floats accept
/// nan and inf, and float32 values below its range become 0 or a subnormal.
/// A leading '+' is accepted. Returns false (writing nothing) otherwise.
bool parse_scalar_token(std::string_view token, ScalarType type, std::byte* out);

/// "line N" for error messages.
std::string line_field(std::size_t number);
/// Shortest decimal text that reads back to exactly `value` (locale independent).
std::string exact_number(double value);

}  // namespace mlidar::io
