// The server's figures in the Prometheus text exposition format (version
// 0.0.4), for GET /metrics: counters and histograms it accumulates, and
// gauges the caller sets just before rendering.
#ifndef ZEBRAGEO_SERVER_METRICS_H_
#define ZEBRAGEO_SERVER_METRICS_H_

#include <map>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

namespace zebrageo {

// Label name -> value, e.g. {{"state", "done"}}.
using MetricLabels = std::vector<std::pair<std::string, std::string>>;

class Metrics {
 public:
  // Declares a metric (name, help, type "counter", "gauge" or "histogram");
  // histograms take their upper bounds (+Inf is added).
  void Declare(const std::string& name, const std::string& help,
               const std::string& type, std::vector<double> buckets = {});
  void Add(const std::string& name, const MetricLabels& labels,
           double amount = 1.0);
  void Set(const std::string& name, const MetricLabels& labels, double value);
  void Observe(const std::string& name, const MetricLabels& labels,
               double value);
  // Every declared metric, in declaration order.
  std::string Render() const;

 private:
  struct Series {
    double value = 0.0;  // counter, gauge; histogram: the sum
    std::vector<double> bucket_counts;
    double count = 0.0;
  };
  struct Metric {
    std::string help;
    std::string type;
    std::vector<double> buckets;
    std::map<std::string, Series> series;  // by rendered labels
  };
  Series& SeriesOf(const std::string& name, const MetricLabels& labels);

  mutable std::mutex mutex_;
  std::vector<std::string> order_;
  std::map<std::string, Metric> metrics_;
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_SERVER_METRICS_H_
