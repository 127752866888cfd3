#include "reports/paper.hpp"

#include <stdexcept>
#include <toml.hpp>

namespace rocklab::reports {

const PaperNumber* Paper::byKey(const std::string& key) const {
  for (const auto& n : numbers) {
    if (n.key == key) return &n;
  }
  return nullptr;
}

const PaperNumber* Paper::byParam(const std::string& param) const {
  for (const auto& n : numbers) {
    if (!n.param.empty() && n.param == param) return &n;
  }
  return nullptr;
}

const PaperNumber* Paper::byResult(const std::string& result) const {
  for (const auto& n : numbers) {
    if (!n.result.empty() && n.result == result) return &n;
  }
  return nullptr;
}

Paper loadPaper(const std::string& path) {
  Paper p;
  try {
    const auto root = toml::parse(path);
    for (const auto& e : toml::find<std::vector<toml::value>>(root, "number")) {
      PaperNumber n;
      n.key = toml::find<std::string>(e, "key");
      const auto& v = toml::find(e, "value");
      n.value = v.is_integer() ? static_cast<double>(v.as_integer()) : v.as_floating();
      n.unit = toml::find<std::string>(e, "unit");
      n.source = toml::find<std::string>(e, "source");
      n.note = toml::find_or<std::string>(e, "note", "");
      n.param = toml::find_or<std::string>(e, "param", "");
      n.result = toml::find_or<std::string>(e, "result", "");
      p.numbers.push_back(std::move(n));
    }
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot read the paper's numbers from '" + path + "': " + e.what());
  }
  return p;
}

}  // namespace rocklab::reports
