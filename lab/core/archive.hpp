#pragma once
// One schema-driven binary serializer. Every stateful type has a single
// `visit(Archive&)` that names its fields; the same function writes and reads, so a
// checkpoint cannot drift between the two (the mistake ESyS-Particle and LAMMPS paid for).
// Field names are stored and checked on reading: a layout change is refused, not
// misread.

#include <array>
#include <cstdint>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include <Eigen/Core>

namespace rocklab {

class CheckpointError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

template <class T>
struct IsEigenFixed : std::false_type {};
template <int R>
struct IsEigenFixed<Eigen::Matrix<double, R, 1>> : std::true_type {};

template <class T>
struct IsArithmeticArray : std::false_type {};
template <class T, std::size_t N>
struct IsArithmeticArray<std::array<T, N>> : std::bool_constant<std::is_arithmetic_v<T>> {};

// Element types stored as plain bytes, so vectors of them are copied in one block.
template <class T>
constexpr bool kPlainBytes =
    std::is_arithmetic_v<T> || IsEigenFixed<T>::value || IsArithmeticArray<T>::value;

template <class T>
concept PlainVector = requires(T v) {
  typename T::value_type;
  v.data();
  v.resize(0);
}
&&kPlainBytes<typename T::value_type>;

class ArchiveWriter {
 public:
  static constexpr bool kReading = false;

  template <class T>
  void operator()(std::string_view name, const T& v) {
    putString(name);
    put(v);
  }
  const std::string& bytes() const { return bytes_; }

 private:
  void raw(const void* p, std::size_t n) {
    if (n > 0)
      bytes_.append(static_cast<const char*>(p), n);  // an empty vector's data() may be null
  }
  void putString(std::string_view s) {
    const auto n = static_cast<std::uint64_t>(s.size());
    raw(&n, sizeof n);
    raw(s.data(), s.size());
  }
  template <class T>
  void put(const T& v) {
    if constexpr (std::is_arithmetic_v<T> || std::is_enum_v<T>) {
      raw(&v, sizeof v);
    } else if constexpr (IsEigenFixed<T>::value) {
      raw(v.data(), sizeof(double) * T::RowsAtCompileTime);
    } else if constexpr (std::is_same_v<T, std::string>) {
      putString(v);
    } else if constexpr (PlainVector<T>) {
      const auto n = static_cast<std::uint64_t>(v.size());
      raw(&n, sizeof n);
      raw(v.data(), n * sizeof(typename T::value_type));
    } else if constexpr (requires {
                           typename T::value_type;
                           v.size();
                           v.begin();
                         }) {
      const auto n = static_cast<std::uint64_t>(v.size());
      raw(&n, sizeof n);
      for (const auto& e : v) put(e);
    } else {
      // A struct with visit(): nested fields.
      const_cast<T&>(v).visit(*this);
    }
  }
  template <class A, class B>
  void put(const std::pair<A, B>& v) {
    put(v.first);
    put(v.second);
  }
  std::string bytes_;
};

class ArchiveReader {
 public:
  static constexpr bool kReading = true;

  ArchiveReader(const char* data, std::size_t size) : p_(data), end_(data + size) {}

  template <class T>
  void operator()(std::string_view name, T& v) {
    const std::string stored = getString();
    if (stored != name) {
      throw CheckpointError("checkpoint layout differs from this build: expected field '" +
                            std::string(name) + "', found '" + stored + "'");
    }
    get(v);
  }
  bool atEnd() const { return p_ == end_; }

 private:
  void raw(void* out, std::size_t n) {
    if (n == 0) return;  // an empty vector's data() may be null
    if (static_cast<std::size_t>(end_ - p_) < n) {
      throw CheckpointError("checkpoint ends early: the file is truncated");
    }
    std::memcpy(out, p_, n);
    p_ += n;
  }
  std::uint64_t count() {
    std::uint64_t n;
    raw(&n, sizeof n);
    if (n > static_cast<std::uint64_t>(end_ - p_)) {
      throw CheckpointError("checkpoint holds an impossible element count: the file is damaged");
    }
    return n;
  }
  std::string getString() {
    const auto n = count();
    std::string s(p_, p_ + n);
    p_ += n;
    return s;
  }
  template <class T>
  void get(T& v) {
    if constexpr (std::is_arithmetic_v<T> || std::is_enum_v<T>) {
      raw(&v, sizeof v);
    } else if constexpr (IsEigenFixed<T>::value) {
      raw(v.data(), sizeof(double) * T::RowsAtCompileTime);
    } else if constexpr (std::is_same_v<T, std::string>) {
      v = getString();
    } else if constexpr (PlainVector<T>) {
      const auto n = count();
      v.resize(n);
      raw(v.data(), n * sizeof(typename T::value_type));
    } else if constexpr (requires {
                           v.resize(0);
                           v.begin();
                         }) {
      const auto n = count();
      v.resize(n);
      for (auto& e : v) get(e);
    } else if constexpr (requires {
                           std::tuple_size<T>::value;
                           v.begin();
                         }) {
      const auto n = count();
      if (n != v.size()) throw CheckpointError("checkpoint array size differs from this build");
      for (auto& e : v) get(e);
    } else {
      v.visit(*this);
    }
  }
  template <class A, class B>
  void get(std::pair<A, B>& v) {
    get(v.first);
    get(v.second);
  }
  const char* p_;
  const char* end_;
};

}  // namespace rocklab
