#pragma once
// Errors the core raises for bad input, carrying what the protocol layer needs to point at
// the offending key: its name, and the allowed range and unit or the rule it breaks.

#include <sstream>
#include <stdexcept>
#include <string>

namespace rocklab {

class InvalidParameter : public std::invalid_argument {
 public:
  // A value outside its allowed range.
  InvalidParameter(std::string where, std::string key, double value, std::string range,
                   std::string unit)
      : InvalidParameter(std::move(where), std::move(key), outside(value, range, unit), 0) {
    range_ = std::move(range);
    unit_ = std::move(unit);
  }
  // A rule across settings that `key` breaks ("must not be below d_min_mm").
  InvalidParameter(std::string where, std::string key, const std::string& why)
      : InvalidParameter(std::move(where), std::move(key), ": " + why, 0) {}

  const std::string& where() const { return where_; }
  const std::string& key() const { return key_; }
  const std::string& range() const { return range_; }
  const std::string& unit() const { return unit_; }
  // What is wrong, after the key: " = -1 is outside the allowed range ..." or ": must ...".
  const std::string& detail() const { return detail_; }
  // The same error about `prefix + key`, raised by `where` (which knows the section).
  InvalidParameter within(const std::string& where, const std::string& prefix) const {
    InvalidParameter e(where, prefix + key_, detail_, 0);
    e.range_ = range_;
    e.unit_ = unit_;
    return e;
  }

 private:
  InvalidParameter(std::string where, std::string key, std::string detail, int)
      : std::invalid_argument(where.empty() ? key + detail : where + ": " + key + detail),
        where_(std::move(where)),
        key_(std::move(key)),
        detail_(std::move(detail)) {}
  static std::string outside(double value, const std::string& range, const std::string& unit) {
    std::ostringstream s;
    s << " = " << value << " is outside the allowed range " << range;
    if (!unit.empty()) s << " (" << unit << ")";
    return s.str();
  }
  std::string where_, key_, detail_, range_, unit_;
};

// Checks lo < value (or <=) and value < hi (or <=), naming the key on failure.
inline void requireRange(const std::string& where, const std::string& key, double value, double lo,
                         bool lo_open, double hi, bool hi_open, const std::string& unit) {
  const bool ok_lo = lo_open ? value > lo : value >= lo;
  const bool ok_hi = hi_open ? value < hi : value <= hi;
  if (ok_lo && ok_hi && value == value) return;
  std::ostringstream r;
  r << (lo_open ? "(" : "[") << lo << ", " << hi << (hi_open ? ")" : "]");
  throw InvalidParameter(where, key, value, r.str(), unit);
}

}  // namespace rocklab
