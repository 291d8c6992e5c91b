#pragma once
// Checkpoints of a run's mutable state (issue #22, docs/checkpoint-plan.md): a tree of named
// groups holding scalars (double, int64, string) and 1-D arrays (double, int64, int32, uint8).
// The state objects (solver, element groups, tools, contacts, measures) write themselves through
// CheckpointWriter and read themselves back through CheckpointReader; neither knows the file
// format. CheckpointTree is the tree in memory and implements both (in-process tests use it
// directly); fem/io/hdf5_checkpoint.hpp writes it to an HDF5 file atomically and reads it back.
//
// A resumed run rebuilds the model exactly as a fresh run does, then overwrites only the mutable
// state: a reader refuses (CheckpointMismatch, naming the object) an object that is missing or an
// array whose size is not the one the rebuilt model expects.
#include <cstdint>
#include <limits>
#include <map>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

namespace ncfsim::fem {

/// A checkpoint that does not fit the model reading it (a missing object, another array size,
/// another kind of object), or that cannot be read. what() names the object ("/solver/x").
class CheckpointMismatch : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline constexpr std::size_t kAnySize = std::numeric_limits<std::size_t>::max();

class CheckpointWriter {
 public:
  virtual ~CheckpointWriter() = default;
  /// Opens (creates) the child group `name` of the current group; end() closes it.
  virtual void begin(const std::string& name) = 0;
  virtual void end() = 0;
  virtual void write_double(const std::string& name, double v) = 0;
  virtual void write_int(const std::string& name, std::int64_t v) = 0;
  virtual void write_string(const std::string& name, const std::string& v) = 0;
  virtual void write_array(const std::string& name, std::span<const double> v) = 0;
  virtual void write_array(const std::string& name, std::span<const std::int64_t> v) = 0;
  virtual void write_array(const std::string& name, std::span<const std::int32_t> v) = 0;
  virtual void write_array(const std::string& name, std::span<const std::uint8_t> v) = 0;
};

class CheckpointReader {
 public:
  virtual ~CheckpointReader() = default;
  /// Enters the child group `name` (CheckpointMismatch when it is missing); end() leaves it.
  virtual void begin(const std::string& name) = 0;
  virtual void end() = 0;
  virtual bool has(const std::string& name) const = 0;  // a scalar, array or group
  virtual double read_double(const std::string& name) const = 0;
  virtual std::int64_t read_int(const std::string& name) const = 0;
  virtual std::string read_string(const std::string& name) const = 0;
  /// The array `name`; CheckpointMismatch when it is missing, of another type or, with
  /// `expected` given, of another size.
  template <class T>
  void read_array(const std::string& name, std::vector<T>& out,
                  std::size_t expected = kAnySize) const {
    read_values(name, out, expected);
  }
  /// Path of the current group ("/solver/groups/000") for messages.
  virtual std::string where() const = 0;
  /// CheckpointMismatch naming `name` in the current group.
  [[noreturn]] void mismatch(const std::string& name, const std::string& why) const {
    throw CheckpointMismatch("checkpoint object '" + where() + (where() == "/" ? "" : "/") + name +
                             "': " + why);
  }
  /// Reads `name` into a fixed-size array of `n` doubles (CheckpointMismatch on another size).
  void read_into(const std::string& name, double* out, std::size_t n) const {
    std::vector<double> v;
    read_array(name, v, n);
    for (std::size_t i = 0; i < n; ++i) out[i] = v[i];
  }
  /// Reads a scalar int64 and checks it equals `expected` (a size or a kind kept as a check).
  void check_int(const std::string& name, std::int64_t expected) const {
    const std::int64_t v = read_int(name);
    if (v != expected)
      mismatch(name, "is " + std::to_string(v) + " in the checkpoint, " + std::to_string(expected) +
                         " in this model");
  }

 protected:
  virtual void read_values(const std::string& name, std::vector<double>& out,
                           std::size_t expected) const = 0;
  virtual void read_values(const std::string& name, std::vector<std::int64_t>& out,
                           std::size_t expected) const = 0;
  virtual void read_values(const std::string& name, std::vector<std::int32_t>& out,
                           std::size_t expected) const = 0;
  virtual void read_values(const std::string& name, std::vector<std::uint8_t>& out,
                           std::size_t expected) const = 0;
};

/// begin(name) on construction, end() on destruction.
template <class Io>
class CheckpointScope {
 public:
  CheckpointScope(Io& io, const std::string& name) : io_(io) { io_.begin(name); }
  ~CheckpointScope() { io_.end(); }
  CheckpointScope(const CheckpointScope&) = delete;
  CheckpointScope& operator=(const CheckpointScope&) = delete;

 private:
  Io& io_;
};

/// A state vector into a checkpoint, and back at the size it has in the rebuilt model.
template <class T>
void save_array(CheckpointWriter& w, const std::string& name, const std::vector<T>& v) {
  w.write_array(name, std::span<const T>(v));
}
template <class T>
void load_array(const CheckpointReader& r, const std::string& name, std::vector<T>& v) {
  r.read_array(name, v, v.size());
}

/// Zero-padded group index ("007") so that groups list in order.
inline std::string checkpoint_index(std::size_t i) {
  std::string s = std::to_string(i);
  return s.size() < 3 ? std::string(3 - s.size(), '0') + s : s;
}

/// The checkpoint as a tree in memory: both a writer (fills it) and a reader (of what it holds).
class CheckpointTree final : public CheckpointWriter, public CheckpointReader {
 public:
  using Value =
      std::variant<double, std::int64_t, std::string, std::vector<double>,
                   std::vector<std::int64_t>, std::vector<std::int32_t>, std::vector<std::uint8_t>>;
  struct Node {
    std::map<std::string, Value> values;
    std::map<std::string, Node> groups;
  };

  CheckpointTree() = default;
  explicit CheckpointTree(Node root) : root_(std::move(root)) {}
  const Node& root() const { return root_; }
  Node& root() { return root_; }

  // Writer.
  void begin(const std::string& name) override {
    if (writing()) {
      path_.push_back(&current()->groups[name]);
      names_.push_back(name);
      return;
    }
    const Node* n = current();
    auto it = n->groups.find(name);
    if (it == n->groups.end()) mismatch(name, "missing (no such group)");
    path_.push_back(const_cast<Node*>(&it->second));
    names_.push_back(name);
  }
  void end() override {
    if (path_.empty()) throw std::logic_error("CheckpointTree::end without begin");
    path_.pop_back();
    names_.pop_back();
  }
  void write_double(const std::string& name, double v) override { put(name, v); }
  void write_int(const std::string& name, std::int64_t v) override { put(name, v); }
  void write_string(const std::string& name, const std::string& v) override { put(name, v); }
  void write_array(const std::string& name, std::span<const double> v) override {
    put(name, std::vector<double>(v.begin(), v.end()));
  }
  void write_array(const std::string& name, std::span<const std::int64_t> v) override {
    put(name, std::vector<std::int64_t>(v.begin(), v.end()));
  }
  void write_array(const std::string& name, std::span<const std::int32_t> v) override {
    put(name, std::vector<std::int32_t>(v.begin(), v.end()));
  }
  void write_array(const std::string& name, std::span<const std::uint8_t> v) override {
    put(name, std::vector<std::uint8_t>(v.begin(), v.end()));
  }

  // Reader.
  bool has(const std::string& name) const override {
    const Node* n = current();
    return n->values.count(name) > 0 || n->groups.count(name) > 0;
  }
  double read_double(const std::string& name) const override { return get<double>(name); }
  std::int64_t read_int(const std::string& name) const override { return get<std::int64_t>(name); }
  std::string read_string(const std::string& name) const override { return get<std::string>(name); }
  std::string where() const override {
    std::string s;
    for (const auto& n : names_) s += "/" + n;
    return s.empty() ? "/" : s;
  }

  /// Switches between filling the tree (the default) and reading it; the path goes back to the
  /// root.
  void set_reading(bool reading) {
    reading_ = reading;
    path_.clear();
    names_.clear();
  }

 protected:
  void read_values(const std::string& name, std::vector<double>& out,
                   std::size_t expected) const override {
    get_array(name, out, expected);
  }
  void read_values(const std::string& name, std::vector<std::int64_t>& out,
                   std::size_t expected) const override {
    get_array(name, out, expected);
  }
  void read_values(const std::string& name, std::vector<std::int32_t>& out,
                   std::size_t expected) const override {
    get_array(name, out, expected);
  }
  void read_values(const std::string& name, std::vector<std::uint8_t>& out,
                   std::size_t expected) const override {
    get_array(name, out, expected);
  }

 private:
  bool writing() const { return !reading_; }
  Node* current() { return path_.empty() ? &root_ : path_.back(); }
  const Node* current() const { return path_.empty() ? &root_ : path_.back(); }
  void put(const std::string& name, Value v) { current()->values[name] = std::move(v); }
  template <class T>
  const T& get(const std::string& name) const {
    const Node* n = current();
    auto it = n->values.find(name);
    if (it == n->values.end()) mismatch(name, "missing");
    const T* p = std::get_if<T>(&it->second);
    if (!p) mismatch(name, "of another type");
    return *p;
  }
  template <class T>
  void get_array(const std::string& name, std::vector<T>& out, std::size_t expected) const {
    const auto& v = get<std::vector<T>>(name);
    if (expected != kAnySize && v.size() != expected)
      mismatch(name, "has " + std::to_string(v.size()) + " values, this model needs " +
                         std::to_string(expected));
    out = v;
  }

  Node root_;
  std::vector<Node*> path_;
  std::vector<std::string> names_;
  bool reading_ = false;
};

}  // namespace ncfsim::fem
