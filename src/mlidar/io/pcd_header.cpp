// PCD header: parsing with strict validation of every line and size.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <optional>
#include <set>

#include "mlidar/core/error.hpp"
#include "mlidar/io/pcd_detail.hpp"

namespace mlidar::io::pcd_detail {
namespace {

enum Keyword : std::size_t { kVersion, kFields, kSize, kType, kCount, kWidth, kHeight, kViewpoint, kPoints, kData, kNumKeywords };
constexpr std::array<std::string_view, kNumKeywords> kKeywordNames = {"VERSION", "FIELDS", "SIZE",      "TYPE",   "COUNT",
                                                                      "WIDTH",   "HEIGHT", "VIEWPOINT", "POINTS", "DATA"};

using Tokens = std::vector<std::string_view>;

std::vector<std::string_view> split_words(std::string_view line) {
  std::vector<std::string_view> words;
  std::size_t pos = 0;
  while (pos < line.size()) {
    const std::size_t start = line.find_first_not_of(" \t\r", pos);
    if (start == std::string_view::npos) break;
    const std::size_t end = std::min(line.find_first_of(" \t\r", start), line.size());
    words.push_back(line.substr(start, end - start));
    pos = end;
  }
  return words;
}

std::optional<std::uint64_t> checked_mul(std::uint64_t a, std::uint64_t b) {
  std::uint64_t product = 0;
  if (__builtin_mul_overflow(a, b, &product)) return std::nullopt;
  return product;
}

std::optional<std::uint64_t> checked_add(std::uint64_t a, std::uint64_t b) {
  std::uint64_t sum = 0;
  if (__builtin_add_overflow(a, b, &sum)) return std::nullopt;
  return sum;
}

class HeaderParser {
 public:
  HeaderParser(std::span<const std::byte> bytes, const std::string& source)
      : text_(reinterpret_cast<const char*>(bytes.data()), bytes.size()), source_(source) {}

  PcdHeader parse() {
    collect_lines();
    require(kVersion, "one version such as 0.7");
    require(kFields, "the field names");
    require(kSize, "one byte size per field");
    require(kType, "one type letter (I, U or F) per field");
    require(kWidth, "the number of points per row");
    require(kHeight, "the number of rows (1 for an unorganised cloud)");
    parse_version();
    parse_fields();
    parse_dimensions();
    parse_viewpoint();
    parse_data_kind();
    compute_sizes();
    return std::move(header_);
  }

 private:
  [[noreturn]] void fail(Keyword keyword, const std::string& problem) const {
    throw InputError(source_, std::string(kKeywordNames[keyword]), problem);
  }

  // Reads lines up to and including DATA; '#' lines and blank lines are comments.
  void collect_lines() {
    std::size_t pos = 0;
    while (pos < text_.size()) {
      const std::size_t newline = text_.find('\n', pos);
      const std::size_t end = newline == std::string_view::npos ? text_.size() : newline;
      const Tokens words = split_words(text_.substr(pos, end - pos));
      pos = newline == std::string_view::npos ? text_.size() : newline + 1;
      if (words.empty() || words[0].front() == '#') continue;
      const Keyword keyword = keyword_of(words[0]);
      if (seen_[keyword]) fail(keyword, "appears twice (expected each header line once)");
      seen_[keyword] = true;
      values_[keyword].assign(words.begin() + 1, words.end());
      if (values_[keyword].empty()) fail(keyword, "has no value");
      if (keyword == kData) {
        header_.data_offset = pos;
        return;
      }
    }
    fail(kData, "missing (the header must end with a DATA line: ascii, binary or binary_compressed)");
  }

  Keyword keyword_of(std::string_view word) const {
    for (std::size_t k = 0; k < kNumKeywords; ++k) {
      if (word == kKeywordNames[k]) return static_cast<Keyword>(k);
    }
    throw InputError(source_, "header",
                     "unknown line " + printable(word) +
                         " (expected VERSION, FIELDS, SIZE, TYPE, COUNT, WIDTH, HEIGHT, VIEWPOINT, POINTS, DATA or a # comment)");
  }

  void require(Keyword keyword, const char* holds) const {
    if (!seen_[keyword]) fail(keyword, std::string("missing header line (expected ") + holds + ")");
  }

  const Tokens& single(Keyword keyword) const {
    if (values_[keyword].size() != 1) fail(keyword, "has " + std::to_string(values_[keyword].size()) + " values (expected 1)");
    return values_[keyword];
  }

  std::uint64_t parse_unsigned(Keyword keyword, std::string_view word, std::uint64_t max_value) const {
    std::uint64_t value = 0;
    const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
    if (ec != std::errc{} || end != word.data() + word.size() || value > max_value) {
      fail(keyword, "value " + printable(word) + " is not an integer in [0, " + std::to_string(max_value) + "]");
    }
    return value;
  }

  void parse_version() {
    const std::string_view version = single(kVersion)[0];
    static constexpr std::array<std::string_view, 6> kKnown = {"0.7", ".7", "0.6", ".6", "0.5", ".5"};
    if (std::find(kKnown.begin(), kKnown.end(), version) == kKnown.end()) {
      fail(kVersion, "is " + printable(version) + " (expected 0.5, 0.6 or 0.7)");
    }
    header_.version = std::string(version);
  }

  void check_per_field(Keyword keyword, std::size_t num_fields) const {
    if (values_[keyword].size() != num_fields) {
      fail(keyword, "has " + std::to_string(values_[keyword].size()) + " values but FIELDS names " + std::to_string(num_fields) +
                        " (expected one per field)");
    }
  }

  ScalarType scalar_type(std::string_view type, std::uint64_t size, const std::string& name) const {
    const bool integer = type == "I" || type == "U";
    if (!integer && type != "F") fail(kType, printable(type) + " of field " + printable(name) + " is unknown (expected I, U or F)");
    const bool is_signed = type == "I";
    switch (size) {
      case 1:
        if (integer) return is_signed ? ScalarType::kI8 : ScalarType::kU8;
        break;
      case 2:
        if (integer) return is_signed ? ScalarType::kI16 : ScalarType::kU16;
        break;
      case 4:
        if (integer) return is_signed ? ScalarType::kI32 : ScalarType::kU32;
        return ScalarType::kF32;
      case 8:
        if (integer) return is_signed ? ScalarType::kI64 : ScalarType::kU64;
        return ScalarType::kF64;
      default:
        break;
    }
    fail(kType, "TYPE " + std::string(type) + " with SIZE " + std::to_string(size) + " for field " + printable(name) +
                    " is not a valid pair (expected I or U with SIZE 1, 2, 4 or 8; F with SIZE 4 or 8)");
  }

  void parse_fields() {
    const Tokens& names = values_[kFields];
    check_per_field(kSize, names.size());
    check_per_field(kType, names.size());
    if (seen_[kCount]) check_per_field(kCount, names.size());
    std::set<std::string_view> unique_names;
    for (std::size_t i = 0; i < names.size(); ++i) {
      PcdField field;
      field.name = std::string(names[i]);
      if (!is_valid_field_name(field.name)) {
        fail(kFields, "name " + printable(field.name) + " holds a control character (expected printable names)");
      }
      if (!field.is_padding() && !unique_names.insert(names[i]).second) {
        fail(kFields, "names " + printable(names[i]) + " twice (expected unique names; only the padding field _ may repeat)");
      }
      field.type =
          scalar_type(values_[kType][i], parse_unsigned(kSize, values_[kSize][i], std::numeric_limits<std::uint32_t>::max()), field.name);
      if (seen_[kCount]) {
        const std::uint64_t count = parse_unsigned(kCount, values_[kCount][i], std::numeric_limits<std::uint32_t>::max());
        if (count == 0) fail(kCount, "of field " + printable(field.name) + " is 0 (expected a positive count)");
        field.count = static_cast<std::uint32_t>(count);
      }
      header_.fields.push_back(std::move(field));
    }
  }

  void parse_dimensions() {
    constexpr std::uint64_t kMax32 = std::numeric_limits<std::uint32_t>::max();
    header_.width = static_cast<std::uint32_t>(parse_unsigned(kWidth, single(kWidth)[0], kMax32));
    header_.height = static_cast<std::uint32_t>(parse_unsigned(kHeight, single(kHeight)[0], kMax32));
    if (header_.height == 0) fail(kHeight, "is 0 (expected at least 1 row)");
    const std::uint64_t expected = std::uint64_t{header_.width} * header_.height;  // < 2^64: both < 2^32
    header_.points = expected;
    if (seen_[kPoints]) {
      const std::uint64_t points = parse_unsigned(kPoints, single(kPoints)[0], std::numeric_limits<std::uint64_t>::max());
      if (points != expected) {
        fail(kPoints,
             "is " + std::to_string(points) + " but WIDTH x HEIGHT = " + std::to_string(expected) + " (expected POINTS = WIDTH * HEIGHT)");
      }
    }
  }

  void parse_viewpoint() {
    if (!seen_[kViewpoint]) return;
    const Tokens& words = values_[kViewpoint];
    if (words.size() != 7) fail(kViewpoint, "has " + std::to_string(words.size()) + " values (expected 7: tx ty tz qw qx qy qz)");
    for (std::size_t i = 0; i < 7; ++i) {
      const std::string_view word = words[i];
      double value = 0.0;
      const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
      if (ec != std::errc{} || end != word.data() + word.size() || !std::isfinite(value)) {
        fail(kViewpoint, "value " + printable(word) + " is not a finite number");
      }
      header_.viewpoint[i] = value;
    }
  }

  void parse_data_kind() {
    const std::string_view kind = single(kData)[0];
    if (kind == "ascii")
      header_.encoding = PcdEncoding::kAscii;
    else if (kind == "binary")
      header_.encoding = PcdEncoding::kBinary;
    else if (kind == "binary_compressed")
      header_.encoding = PcdEncoding::kBinaryCompressed;
    else
      fail(kData, "kind " + printable(kind) + " is unknown (expected ascii, binary or binary_compressed)");
  }

  // Sizes used to bound reads and allocations; all products checked for overflow.
  void compute_sizes() {
    std::uint64_t record = 0;
    std::uint64_t values = 0;
    for (const PcdField& field : header_.fields) {
      const auto r = checked_add(record, field.stride());
      const auto v = checked_add(values, field.count);
      if (!r || !v) fail(kCount, "makes the point record size overflow (expected realistic SIZE x COUNT)");
      record = *r;
      values = *v;
    }
    if (!checked_mul(header_.points, record) || !checked_mul(header_.points, values)) {
      fail(kPoints, std::to_string(header_.points) + " points of " + std::to_string(record) +
                        " bytes overflow 64 bits (expected a realistic point count)");
    }
    header_.record_size = record;
    header_.values_per_point = values;
  }

  std::string_view text_;
  const std::string& source_;
  std::array<bool, kNumKeywords> seen_{};
  std::array<Tokens, kNumKeywords> values_{};
  PcdHeader header_;
};

}  // namespace

bool is_valid_field_name(std::string_view name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    const auto byte = static_cast<unsigned char>(c);
    return byte > 0x20 && byte != 0x7f;
  });
}

std::string printable(std::string_view text) {
  constexpr std::size_t kMaxShown = 40;
  std::string out = "'";
  for (std::size_t i = 0; i < text.size() && i < kMaxShown; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    out += (c >= 0x20 && c < 0x7f) ? static_cast<char>(c) : '?';
  }
  if (text.size() > kMaxShown) out += "...";
  return out + "'";
}

PcdHeader parse_pcd_header(std::span<const std::byte> bytes, const std::string& source) { return HeaderParser(bytes, source).parse(); }

PointTable make_table(const PcdHeader& header) {
  PointTable table;
  table.num_points = static_cast<std::size_t>(header.points);
  table.width = header.width;
  table.height = header.height;
  table.fields.reserve(header.fields.size());
  for (const PcdField& field : header.fields) table.add_field(field.name, field.type, field.count);
  return table;
}

}  // namespace mlidar::io::pcd_detail
