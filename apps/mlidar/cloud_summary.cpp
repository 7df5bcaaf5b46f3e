#include "apps/mlidar/cloud_summary.hpp"

#include <cmath>
#include <set>
#include <sstream>

namespace mlidar::cli {
namespace {

const io::FieldColumn* first_present(const io::PointTable& table, const auto& names) {
  for (const char* name : names) {
    if (const auto* field = table.find(name)) return field;
  }
  return nullptr;
}

void summarize_geometry(const io::PointTable& table, CloudSummary& summary) {
  const auto* fx = table.find("x");
  const auto* fy = table.find("y");
  const auto* fz = table.find("z");
  if (fx == nullptr || fy == nullptr || fz == nullptr) return;
  Eigen::AlignedBox3d box;
  for (std::size_t i = 0; i < table.num_points; ++i) {
    const Eigen::Vector3d p(fx->value(i), fy->value(i), fz->value(i));
    if (!p.allFinite()) {
      ++summary.nan_points;
      continue;
    }
    box.extend(p);
  }
  if (!box.isEmpty()) summary.bounds = box;
}

}  // namespace

CloudSummary summarize(const std::string& path, const io::CloudFile& cloud) {
  const io::PointTable& table = cloud.table;
  CloudSummary summary;
  summary.path = path;
  summary.format = io::cloud_format_name(cloud.format);
  summary.encoding = cloud.encoding;
  summary.points = table.num_points;
  summary.width = table.width;
  summary.height = table.height;
  for (const auto& field : table.fields) {
    summary.field_types.push_back({field.name, field.type, field.count, {}});
  }
  summarize_geometry(table, summary);
  if (table.find("x") && table.find("y") && table.find("z") && first_present(table, io::kTimeFieldNames)) {
    const Scan scan = io::to_scan(table, path, io::ScanOptions{true});
    summary.time_field = first_present(table, io::kTimeFieldNames)->name;
    for (float t : scan.time) summary.time_span_s = std::max(summary.time_span_s, static_cast<double>(t));
  }
  if (const auto* ring = first_present(table, io::kRingFieldNames)) {
    summary.ring_field = ring->name;
    std::set<double> rings;
    for (std::size_t i = 0; i < table.num_points; ++i) rings.insert(ring->value(i));
    summary.ring_count = rings.size();
  }
  return summary;
}

std::string format_text(const CloudSummary& s) {
  std::ostringstream out;
  out << s.path << '\n';
  out << "  format    " << s.format << " (" << s.encoding << ")\n";
  out << "  points    " << s.points;
  if (s.height > 1) out << " (organised " << s.width << " x " << s.height << ")";
  out << '\n' << "  fields   ";
  for (const auto& f : s.field_types) {
    out << ' ' << f.name << ':' << io::scalar_name(f.type);
    if (f.count > 1) out << 'x' << f.count;
  }
  out << '\n' << "  NaN points " << s.nan_points << '\n';
  if (s.bounds) {
    out << "  bounds    min [" << s.bounds->min().transpose() << "] max [" << s.bounds->max().transpose() << "] m\n";
  }
  if (s.time_field) out << "  time      field '" << *s.time_field << "', span " << s.time_span_s << " s\n";
  if (s.ring_field) out << "  rings     " << s.ring_count << " (field '" << *s.ring_field << "')\n";
  return out.str();
}

nlohmann::json to_json(const CloudSummary& s) {
  nlohmann::json fields = nlohmann::json::array();
  for (const auto& f : s.field_types) {
    fields.push_back({{"name", f.name}, {"type", io::scalar_name(f.type)}, {"count", f.count}});
  }
  nlohmann::json j = {{"path", s.path},   {"format", s.format}, {"encoding", s.encoding}, {"points", s.points},
                      {"width", s.width}, {"height", s.height}, {"fields", fields},       {"nan_points", s.nan_points}};
  if (s.bounds) {
    const auto& lo = s.bounds->min();
    const auto& hi = s.bounds->max();
    j["bounds"] = {{"min", {lo.x(), lo.y(), lo.z()}}, {"max", {hi.x(), hi.y(), hi.z()}}};
  }
  if (s.time_field) j["time"] = {{"field", *s.time_field}, {"span_s", s.time_span_s}};
  if (s.ring_field) j["rings"] = {{"field", *s.ring_field}, {"count", s.ring_count}};
  return j;
}

}  // namespace mlidar::cli
