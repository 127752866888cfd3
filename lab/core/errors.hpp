#pragma once
// Errors the core raises for bad input, carrying what the protocol layer needs to point at
// the offending key: its name, the allowed range and the unit.

#include <sstream>
#include <stdexcept>
#include <string>

namespace rocklab {

class InvalidParameter : public std::invalid_argument {
 public:
  InvalidParameter(std::string where, std::string key, double value, std::string range,
                   std::string unit)
      : std::invalid_argument(format(where, key, value, range, unit)),
        key_(std::move(key)),
        range_(std::move(range)),
        unit_(std::move(unit)) {}
  const std::string& key() const { return key_; }
  const std::string& range() const { return range_; }
  const std::string& unit() const { return unit_; }

 private:
  static std::string format(const std::string& where, const std::string& key, double value,
                            const std::string& range, const std::string& unit) {
    std::ostringstream s;
    s << where << ": " << key << " = " << value << " is outside the allowed range " << range;
    if (!unit.empty()) s << " (" << unit << ")";
    return s.str();
  }
  std::string key_, range_, unit_;
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
