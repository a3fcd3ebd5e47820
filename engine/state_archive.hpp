#pragma once
// The whole state of a run as bytes, for checkpoints (`--checkpoint-every`, `kushner resume`). One visiting
// function per stateful object (`visit_state(archive)`) serves both directions: saving appends each named
// block, loading reads the blocks back in the same order into the same views. A block whose name, shape or
// element size differs from what the run being resumed allocates is an InputError: the checkpoint belongs to
// another model or option set.
#include "core/errors.hpp"

#include <Kokkos_Core.hpp>

#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

namespace kushner {

class StateArchive {
 public:
  /// An empty archive that saves.
  StateArchive() = default;
  /// An archive that loads from `bytes` (which must outlive it).
  explicit StateArchive(const std::string& bytes) : input_(&bytes) {}

  bool loading() const { return input_ != nullptr; }

  /// Put before every name from now on (e.g. "EKF.": the filter whose state is visited).
  std::string scope;
  /// What has been saved.
  const std::string& bytes() const { return output_; }

  /// A Kokkos view's elements, in its memory order (the view is contiguous: allocated, not a subview).
  template <class View>
  void view(const std::string& name, const View& v) {
    using T = typename View::non_const_value_type;
    static_assert(std::is_trivially_copyable_v<T>, "StateArchive: view elements must be trivially copyable");
    KUSHNER_REQUIRE(v.span_is_contiguous(), "StateArchive: view '" << name << "' is not contiguous");
    std::vector<std::uint64_t> shape(View::rank);
    for (std::size_t r = 0; r < View::rank; ++r) shape[r] = v.extent(r);
    const std::size_t bytes = v.span() * sizeof(T);
    if (!loading()) {
      put_header(name, sizeof(T), shape);
      const auto host = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), v);
      put(host.data(), bytes);
      return;
    }
    get_header(name, sizeof(T), shape);
    const auto host = Kokkos::create_mirror_view(v);
    get(host.data(), bytes);
    Kokkos::deep_copy(v, host);
  }

  /// One trivially copyable value.
  template <class T>
  void value(const std::string& name, T& x) {
    static_assert(std::is_trivially_copyable_v<T>, "StateArchive: values must be trivially copyable");
    if (!loading()) {
      put_header(name, sizeof(T), std::vector<std::uint64_t>());
      put(&x, sizeof(T));
    } else {
      get_header(name, sizeof(T), std::vector<std::uint64_t>());
      get(&x, sizeof(T));
    }
  }

  /// A vector of trivially copyable values; loading resizes it.
  template <class T>
  void values(const std::string& name, std::vector<T>& x) {
    static_assert(std::is_trivially_copyable_v<T>, "StateArchive: values must be trivially copyable");
    if (!loading()) {
      put_header(name, sizeof(T), std::vector<std::uint64_t>(1, x.size()));
      put(x.data(), x.size() * sizeof(T));
    } else {
      x.resize(get_length(name, sizeof(T)));
      get(x.data(), x.size() * sizeof(T));
    }
  }

  void text(const std::string& name, std::string& s) {
    if (!loading()) {
      put_header(name, 1, std::vector<std::uint64_t>(1, s.size()));
      put(s.data(), s.size());
    } else {
      s.resize(get_length(name, 1));
      get(s.data(), s.size());
    }
  }

  /// Saves `expected`; on loading, requires the saved text to equal it (what the run must match, e.g. its
  /// arguments), InputError naming `what` otherwise.
  void require_equal(const std::string& name, const std::string& expected, const std::string& what) {
    std::string saved = expected;
    text(name, saved);
    if (saved == expected) return;
    const bool short_texts = saved.size() + expected.size() < 80;
    KUSHNER_INPUT_REQUIRE(false, "checkpoint: written for another "
                                     << what
                                     << (short_texts ? " ('" + saved + "' there, '" + expected + "' here)"
                                                     : " (a file the run reads, or its arguments, changed since)"));
  }

  /// Loading: every byte was read (InputError otherwise: a checkpoint of a longer state).
  void finish() const {
    if (loading())
      KUSHNER_INPUT_REQUIRE(position_ == input_->size(),
                            "checkpoint: " << input_->size() - position_ << " bytes left over: written by another run");
  }

 private:
  void put(const void* data, std::size_t bytes) { output_.append(static_cast<const char*>(data), bytes); }
  template <class T>
  void put_number(T x) {
    put(&x, sizeof x);
  }
  void get(void* data, std::size_t bytes) {
    KUSHNER_INPUT_REQUIRE(input_->size() - position_ >= bytes, "checkpoint: state ends early (truncated file)");
    if (bytes > 0) std::memcpy(data, input_->data() + position_, bytes);
    position_ += bytes;
  }
  template <class T>
  T get_number() {
    T x;
    get(&x, sizeof x);
    return x;
  }

  void put_header(const std::string& local_name, std::size_t element_size, const std::vector<std::uint64_t>& shape) {
    const std::string name = scope + local_name;
    put_number<std::uint32_t>(static_cast<std::uint32_t>(name.size()));
    put(name.data(), name.size());
    put_number<std::uint32_t>(static_cast<std::uint32_t>(element_size));
    put_number<std::uint32_t>(static_cast<std::uint32_t>(shape.size()));
    for (const std::uint64_t e : shape) put_number(e);
  }

  /// Reads a block's header and requires it to be `name` with this element size and shape.
  void get_header(const std::string& local_name, std::size_t element_size, const std::vector<std::uint64_t>& shape) {
    const std::string name = scope + local_name;
    const std::vector<std::uint64_t> saved = read_header(name, element_size);
    KUSHNER_INPUT_REQUIRE(saved == shape, "checkpoint: '" << name << "' has shape " << shape_text(saved) << " there, "
                                                          << shape_text(shape)
                                                          << " here: written for another model or option set");
  }
  /// Reads a vector's header; returns its length.
  std::size_t get_length(const std::string& local_name, std::size_t element_size) {
    const std::string name = scope + local_name;
    const std::vector<std::uint64_t> saved = read_header(name, element_size);
    KUSHNER_INPUT_REQUIRE(saved.size() == 1, "checkpoint: '" << name << "' is not a list there");
    KUSHNER_INPUT_REQUIRE(saved[0] <= (input_->size() - position_) / element_size,
                          "checkpoint: state ends early (truncated file)");
    return static_cast<std::size_t>(saved[0]);
  }
  std::vector<std::uint64_t> read_header(const std::string& name, std::size_t element_size) {
    const auto length = get_number<std::uint32_t>();
    KUSHNER_INPUT_REQUIRE(length <= input_->size() - position_, "checkpoint: state ends early (truncated file)");
    std::string saved(length, '\0');
    get(saved.data(), length);
    KUSHNER_INPUT_REQUIRE(saved == name, "checkpoint: found '" << saved << "' where this run has '" << name
                                                               << "': written for another model or option set");
    KUSHNER_INPUT_REQUIRE(get_number<std::uint32_t>() == element_size,
                          "checkpoint: '" << name << "' has another element size: written by another build");
    const auto rank = get_number<std::uint32_t>();
    KUSHNER_INPUT_REQUIRE(rank <= 8, "checkpoint: '" << name << "' has rank " << rank << " (corrupt)");
    std::vector<std::uint64_t> shape(rank);
    for (auto& e : shape) e = get_number<std::uint64_t>();
    return shape;
  }
  static std::string shape_text(const std::vector<std::uint64_t>& shape) {
    std::string s = "(";
    for (std::size_t i = 0; i < shape.size(); ++i) s += (i ? ", " : "") + std::to_string(shape[i]);
    return s + ")";
  }

  const std::string* input_ = nullptr;
  std::size_t position_ = 0;
  std::string output_;
};

}  // namespace kushner
