#include "server/metrics.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace zebrageo {
namespace {

// A label value escaped as the format wants: backslash, quote, newline.
std::string Escaped(const std::string& value) {
  std::string out;
  for (char c : value) {
    if (c == '\\' || c == '"') out += '\\';
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    out += c;
  }
  return out;
}

std::string LabelText(const MetricLabels& labels) {
  std::string text;
  for (const auto& [name, value] : labels) {
    text += (text.empty() ? "" : ",") + name + "=\"" + Escaped(value) + "\"";
  }
  return text;
}

std::string Number(double value) {
  if (std::isinf(value)) return value > 0 ? "+Inf" : "-Inf";
  std::ostringstream out;
  out.precision(10);
  out << value;
  return out.str();
}

// name{labels} or name{labels,extra}.
std::string SeriesName(const std::string& name, const std::string& labels,
                       const std::string& extra = "") {
  std::string all = labels;
  if (!extra.empty()) all += (all.empty() ? "" : ",") + extra;
  return all.empty() ? name : name + "{" + all + "}";
}

}  // namespace

void Metrics::Declare(const std::string& name, const std::string& help,
                      const std::string& type, std::vector<double> buckets) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (metrics_.count(name) == 0) order_.push_back(name);
  Metric& metric = metrics_[name];
  metric.help = help;
  metric.type = type;
  metric.buckets = std::move(buckets);
}

Metrics::Series& Metrics::SeriesOf(const std::string& name,
                                   const MetricLabels& labels) {
  auto it = metrics_.find(name);
  if (it == metrics_.end()) throw std::logic_error("metric " + name);
  Series& series = it->second.series[LabelText(labels)];
  series.bucket_counts.resize(it->second.buckets.size());
  return series;
}

void Metrics::Add(const std::string& name, const MetricLabels& labels,
                  double amount) {
  std::lock_guard<std::mutex> lock(mutex_);
  SeriesOf(name, labels).value += amount;
}

void Metrics::Set(const std::string& name, const MetricLabels& labels,
                  double value) {
  std::lock_guard<std::mutex> lock(mutex_);
  SeriesOf(name, labels).value = value;
}

void Metrics::Observe(const std::string& name, const MetricLabels& labels,
                      double value) {
  std::lock_guard<std::mutex> lock(mutex_);
  Series& series = SeriesOf(name, labels);
  const std::vector<double>& buckets = metrics_[name].buckets;
  for (size_t i = 0; i < buckets.size(); ++i) {
    if (value <= buckets[i]) series.bucket_counts[i] += 1.0;
  }
  series.value += value;
  series.count += 1.0;
}

std::string Metrics::Render() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::ostringstream out;
  for (const std::string& name : order_) {
    const Metric& metric = metrics_.at(name);
    out << "# HELP " << name << " " << metric.help << "\n";
    out << "# TYPE " << name << " " << metric.type << "\n";
    for (const auto& [labels, series] : metric.series) {
      if (metric.type != "histogram") {
        out << SeriesName(name, labels) << " " << Number(series.value) << "\n";
        continue;
      }
      for (size_t i = 0; i < metric.buckets.size(); ++i) {
        out << SeriesName(name + "_bucket", labels,
                          "le=\"" + Number(metric.buckets[i]) + "\"")
            << " " << Number(series.bucket_counts[i]) << "\n";
      }
      out << SeriesName(name + "_bucket", labels, "le=\"+Inf\"") << " "
          << Number(series.count) << "\n";
      out << SeriesName(name + "_sum", labels) << " " << Number(series.value)
          << "\n";
      out << SeriesName(name + "_count", labels) << " " << Number(series.count)
          << "\n";
    }
  }
  return out.str();
}

}  // namespace zebrageo
