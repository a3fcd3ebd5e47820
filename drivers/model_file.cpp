#include "models/polynomial_spec.hpp"

#include "core/errors.hpp"
#include "drivers/toml_characters.hpp"
#include "models/polynomial_monomials.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

namespace kushner {

namespace {

const char* type_name(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::table: return "a table";
    case toml::node_type::array: return "an array";
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a number";
    case toml::node_type::boolean: return "a boolean";
    default: return "a date or time";
  }
}

std::string shape_text(const std::vector<int>& dims) {
  std::string s;
  for (std::size_t i = 0; i < dims.size(); ++i)
    s += (i ? "x" : "") + (dims[i] < 0 ? std::string("k") : std::to_string(dims[i]));
  return s;
}

/// Reads one model file's tables, naming the file and the key in every error.
class ModelFileReader {
 public:
  explicit ModelFileReader(std::string path) : path_(std::move(path)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& message) const {
    throw InputError(path_ + ": " + key + ": " + message);
  }

  /// Refuses keys of `table` (named `prefix`) that are not in `known`.
  void only_known_keys(const toml::table& table, const std::string& prefix,
                       const std::vector<std::string>& known) const {
    for (auto&& [key, node] : table) {
      const std::string name(key.str());
      if (std::find(known.begin(), known.end(), name) != known.end()) continue;
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      fail(prefix + name, "unknown key (known here: " + list + ")");
    }
  }

  const toml::table* table(const toml::table& parent, const std::string& name, bool required) const {
    const toml::node* node = parent.get(name);
    if (node == nullptr) {
      if (required) fail(name, "missing (required table [" + name + "])");
      return nullptr;
    }
    if (!node->is_table()) fail(name, std::string("expected a table [") + name + "], got " + type_name(*node));
    return node->as_table();
  }

  double number(const toml::node& node, const std::string& key) const {
    if (const auto* i = node.as_integer()) return static_cast<double>(i->get());
    const auto* f = node.as_floating_point();
    if (f == nullptr) fail(key, std::string("expected a number, got ") + type_name(node));
    if (!std::isfinite(f->get())) fail(key, "not finite");
    return f->get();
  }

  long integer(const toml::node& node, const std::string& key) const {
    const auto* i = node.as_integer();
    if (i == nullptr) fail(key, std::string("expected an integer, got ") + type_name(node));
    return i->get();
  }

  /// A nested array of numbers of shape `dims` (an entry -1: any length >= 1, the same for every array at that
  /// depth; filled in), row-major into `out`.
  void array(const toml::node& node, const std::string& key, std::vector<int>& dims, std::vector<double>& out) const {
    const std::vector<int> wanted = dims;
    out.clear();
    read_level(node, key, key, 0, wanted, dims, out);
  }

  /// array() of the key `name` of `table` (named `prefix`); false when absent and not required.
  bool array(const toml::table* table, const std::string& prefix, const std::string& name, bool required,
             std::vector<int>& dims, std::vector<double>& out) const {
    const toml::node* node = table ? table->get(name) : nullptr;
    if (node == nullptr) {
      if (required) fail(prefix + name, "missing (required: a " + shape_text(dims) + " array)");
      return false;
    }
    array(*node, prefix + name, dims, out);
    return true;
  }

 private:
  void read_level(const toml::node& node, const std::string& key, const std::string& where, std::size_t level,
                  const std::vector<int>& wanted, std::vector<int>& dims, std::vector<double>& out) const {
    const std::string expected = "expected a " + shape_text(wanted) + " array";
    if (level == dims.size()) {
      if (!node.is_integer() && !node.is_floating_point())
        fail(key, expected + ", but " + where + " is " + type_name(node));
      out.push_back(number(node, where));
      return;
    }
    const toml::array* a = node.as_array();
    if (a == nullptr)
      fail(key, expected + ", but " + (level == 0 ? std::string("it") : where) + " is " + type_name(node));
    const int size = static_cast<int>(a->size());
    if (dims[level] < 0 && size >= 1) dims[level] = size;
    if (size != dims[level])
      fail(key, expected + ", but " + (level == 0 ? std::string("it") : where) + " has " + std::to_string(size) +
                    (size == 1 ? " entry" : " entries"));
    for (int i = 0; i < size; ++i)
      read_level(*a->get(i), key, where + "[" + std::to_string(i) + "]", level + 1, wanted, dims, out);
  }

  std::string path_;
};

/// The monomial index of sorted variable indices (degree 2..4) in polynomial_monomial() order.
std::map<std::vector<int>, int> monomial_indices(int n) {
  std::map<std::vector<int>, int> index;
  for (int t = 0; t < polynomial_monomial_count(n); ++t) {
    const Monomial m = polynomial_monomial(n, t);
    index[std::vector<int>(m.var, m.var + m.degree)] = t;
  }
  return index;
}

/// One polynomial of the file, g_k(x) = c0_k + sum_i c1_ki x_i + sum of monomials of degree 2..max_degree, for
/// k < rows: the drift or transition (rows = n, a0..a4, [[drift.terms]]) or the observation (rows = p, c0..c3 or
/// C for c1, [[observation.terms]]). Tensors and terms are summed into one coefficient per monomial.
struct PolynomialPart {
  std::string prefix;  // "drift.", "transition." or "observation."
  char letter;         // 'a' or 'c': the tensors' names
  int max_degree;
  int rows;  // -1: the first tensor found sets it (the observation's p)
  std::vector<double> constant, linear, monomial;
};

void read_polynomial(const ModelFileReader& in, const toml::table* table, int n, PolynomialPart& part) {
  const int num_monomials = polynomial_monomial_count(n);
  const std::map<std::vector<int>, int> monomial = monomial_indices(n);
  std::vector<std::vector<double>> tensors(part.max_degree + 1);
  std::vector<bool> given(part.max_degree + 1, false);
  for (int degree = 0; degree <= part.max_degree; ++degree) {
    std::string name = part.letter + std::to_string(degree);
    if (part.letter == 'c' && degree == 1 && table && table->get("C")) {
      if (table->get("c1")) in.fail(part.prefix + "C", "give C or c1 (the same matrix), not both");
      name = "C";
    }
    std::vector<int> dims(degree + 1, n);
    dims[0] = part.rows;
    if (degree == 0 && part.rows < 0) continue;  // c0 is read once the rows are known
    given[degree] = in.array(table, part.prefix, name, false, dims, tensors[degree]);
    if (given[degree]) part.rows = dims[0];
  }
  if (part.rows < 0)
    in.fail(part.prefix + "C", "missing (required: the observation's linear part C, p x n, or one of c1, c2, c3)");
  if (part.letter == 'c') {  // now that p is known
    std::vector<int> dims = {part.rows};
    given[0] = in.array(table, part.prefix, "c0", false, dims, tensors[0]);
  }
  part.constant.assign(part.rows, 0.0);
  part.linear.assign(part.rows * n, 0.0);
  part.monomial.assign(part.rows * num_monomials, 0.0);
  // Adds c x_vars[0] ... x_vars[d-1] to g_k.
  auto add_term = [&](int k, std::vector<int> vars, double c) {
    std::sort(vars.begin(), vars.end());
    if (vars.empty())
      part.constant[k] += c;
    else if (vars.size() == 1)
      part.linear[k * n + vars[0]] += c;
    else
      part.monomial[k * num_monomials + monomial.at(vars)] += c;
  };
  for (int degree = 0; degree <= part.max_degree; ++degree) {
    if (!given[degree]) continue;
    const std::vector<double>& values = tensors[degree];
    for (std::size_t flat = 0; flat < values.size(); ++flat) {
      std::vector<int> vars(degree);
      std::size_t rest = flat;
      for (int r = degree - 1; r >= 0; --r, rest /= n) vars[r] = static_cast<int>(rest % n);
      add_term(static_cast<int>(rest), vars, values[flat]);
    }
  }
  const std::string terms_key = part.prefix + "terms";
  if (const toml::node* terms = table ? table->get("terms") : nullptr) {
    const toml::array* list = terms->as_array();
    if (list == nullptr || !list->is_array_of_tables())
      in.fail(terms_key, std::string("expected [[") + terms_key + "]] tables, got " + type_name(*terms));
    for (std::size_t i = 0; i < list->size(); ++i) {
      const std::string key = terms_key + "[" + std::to_string(i) + "]";
      const toml::table& term = *list->get(i)->as_table();
      in.only_known_keys(term, key + ".", {"component", "powers", "coefficient"});
      for (const char* required : {"component", "powers", "coefficient"})
        if (term.get(required) == nullptr) in.fail(key + "." + required, "missing");
      const long k = in.integer(*term.get("component"), key + ".component");
      if (k < 1 || k > part.rows)
        in.fail(key + ".component",
                "must be in 1 .. " + std::to_string(part.rows) + " (got " + std::to_string(k) + ")");
      const toml::array* powers = term.get("powers")->as_array();
      if (powers == nullptr || static_cast<int>(powers->size()) != n)
        in.fail(key + ".powers", "expected an array of " + std::to_string(n) + " exponents (one per state)");
      std::vector<int> vars;
      for (int v = 0; v < n; ++v) {
        const long e = in.integer(*powers->get(v), key + ".powers[" + std::to_string(v) + "]");
        if (e < 0) in.fail(key + ".powers[" + std::to_string(v) + "]", "must not be negative");
        if (e > part.max_degree || static_cast<long>(vars.size()) + e > part.max_degree)
          in.fail(key + ".powers", "total degree above " + std::to_string(part.max_degree));
        vars.insert(vars.end(), e, v);
      }
      add_term(static_cast<int>(k - 1), vars, in.number(*term.get("coefficient"), key + ".coefficient"));
    }
  }
  for (const auto* coefficients : {&part.constant, &part.linear, &part.monomial})
    for (double c : *coefficients)
      if (!std::isfinite(c))
        in.fail(part.prefix.substr(0, part.prefix.size() - 1), "coefficients overflow when summed");
}

PolynomialModelSpec read_spec(const toml::table& root, const std::string& path) {
  const ModelFileReader in(path);
  PolynomialModelSpec spec;
  spec.path = path;
  if (const toml::node* time = root.get("time")) {
    const auto* text = time->as_string();
    if (text == nullptr || (text->get() != "continuous" && text->get() != "discrete"))
      in.fail("time", "expected \"continuous\" or \"discrete\"");
    spec.discrete = text->get() == "discrete";
  }
  // The tables of the two times: dx = f dt + b dw, or x[k+1] = F(x) + G e.
  const std::string f_table = spec.discrete ? "transition" : "drift";
  const std::string noise_table = spec.discrete ? "process_noise" : "diffusion", noise_key = spec.discrete ? "G" : "b";
  for (const char* other : {"drift", "diffusion", "transition", "process_noise"})
    if (other != f_table && other != noise_table && root.get(other) != nullptr)
      in.fail(other, spec.discrete ? "a discrete-time model (time = \"discrete\") has [transition] and "
                                     "[process_noise], not [drift] and [diffusion]"
                                   : "a continuous-time model has [drift] and [diffusion]; [transition] and "
                                     "[process_noise] are a discrete one's (time = \"discrete\")");
  in.only_known_keys(
      root, "",
      {"state_dim", "time", "name", "description", f_table, noise_table, "observation", "control", "initial"});

  const toml::node* dim = root.get("state_dim");
  if (dim == nullptr) in.fail("state_dim", "missing (required: the state dimension, 1, 2 or 3)");
  const long n = in.integer(*dim, "state_dim");
  if (n < 1 || n > 3) in.fail("state_dim", "must be 1, 2 or 3 (got " + std::to_string(n) + ")");
  spec.n = static_cast<int>(n);
  for (const char* key : {"name", "description"}) {
    const toml::node* node = root.get(key);
    if (node == nullptr) continue;
    if (!node->is_string()) in.fail(key, std::string("expected a string, got ") + type_name(*node));
    (std::string(key) == "name" ? spec.label : spec.description) = node->as_string()->get();
  }

  // Drift (or transition): the tensors contracted with x, summed into one coefficient per monomial.
  const toml::table* drift = in.table(root, f_table, false);
  if (drift) in.only_known_keys(*drift, f_table + ".", {"a0", "a1", "a2", "a3", "a4", "terms"});
  PolynomialPart f{f_table + ".", 'a', 4, spec.n, {}, {}, {}};
  read_polynomial(in, drift, spec.n, f);
  spec.a0 = std::move(f.constant);
  spec.a1 = std::move(f.linear);
  spec.monomial = std::move(f.monomial);

  // Diffusion b (or the process noise's G), n x q.
  const toml::table* noise = in.table(root, noise_table, true);
  const std::string noise_name = noise_table + "." + noise_key;
  in.only_known_keys(*noise, noise_table + ".", {noise_key});
  std::vector<int> b_dims = {spec.n, -1};
  in.array(noise, noise_table + ".", noise_key, true, b_dims, spec.b);
  spec.q = b_dims[1];
  if (spec.q > spec.n)
    in.fail(noise_name, "has " + std::to_string(spec.q) + " columns, at most state_dim = " + std::to_string(spec.n) +
                            " (give an n x n matrix with the same " + noise_key + " " + noise_key + "^T)");

  // Observation: h of degree <= 3, like the drift; p rows (the first tensor given sets p).
  const toml::table* observation = in.table(root, "observation", true);
  in.only_known_keys(*observation, "observation.", {"c0", "C", "c1", "c2", "c3", "terms", "R"});
  PolynomialPart h{"observation.", 'c', 3, -1, {}, {}, {}};
  read_polynomial(in, observation, spec.n, h);
  spec.p = h.rows;
  if (spec.p > spec.n)
    in.fail("observation", "has " + std::to_string(spec.p) + " rows, at most state_dim = " + std::to_string(spec.n));
  spec.c0 = std::move(h.constant);
  spec.C = std::move(h.linear);
  spec.observation_monomial = std::move(h.monomial);
  std::vector<int> R_dims = {spec.p, spec.p};
  in.array(observation, "observation.", "R", true, R_dims, spec.R);

  // Control input: one column B (n entries, or an n x 1 matrix); absent: no input.
  if (const toml::table* control = in.table(root, "control", false)) {
    in.only_known_keys(*control, "control.", {"B"});
    const toml::node* B = control->get("B");
    if (B == nullptr) in.fail("control.B", "missing (required: the input's column, n entries)");
    const toml::array* a = B->as_array();
    std::vector<int> dims = {spec.n};
    if (a != nullptr && !a->empty() && a->get(0)->is_array()) dims = {spec.n, 1};
    in.array(*B, "control.B", dims, spec.B);
  }
  // Initial laws.
  const toml::table* initial = in.table(root, "initial", true);
  in.only_known_keys(*initial, "initial.", {"x0_mean", "x0_cov", "prior_mean", "prior_cov"});
  std::vector<int> vector_dims = {spec.n}, matrix_dims = {spec.n, spec.n};
  in.array(initial, "initial.", "x0_mean", true, vector_dims, spec.x0_mean);
  in.array(initial, "initial.", "x0_cov", true, matrix_dims, spec.x0_cov);
  if (!in.array(initial, "initial.", "prior_mean", false, vector_dims, spec.prior_mean)) spec.prior_mean = spec.x0_mean;
  if (!in.array(initial, "initial.", "prior_cov", false, matrix_dims, spec.prior_cov)) spec.prior_cov = spec.x0_cov;
  return spec;
}

}  // namespace

PolynomialModelSpec parse_polynomial_model(const std::string& text, const std::string& path) {
  check_toml_characters(text, path);  // before toml++ sees it: drivers/toml_characters.hpp
  toml::table root;
  try {
    root = toml::parse(text, path);
  } catch (const toml::parse_error& e) {
    std::ostringstream message;
    message << path << ": line " << e.source().begin.line << ", column " << e.source().begin.column
            << ": not TOML: " << e.description();
    throw InputError(message.str());
  }
  return read_spec(root, path);
}

PolynomialModelSpec read_polynomial_model_file(const std::string& path) {
  KUSHNER_INPUT_REQUIRE(std::filesystem::is_regular_file(path), "--model-file: cannot read '" << path << "'");
  std::ifstream file(path, std::ios::binary);
  std::ostringstream text;
  text << file.rdbuf();
  KUSHNER_INPUT_REQUIRE(file.good() || file.eof(), "--model-file: cannot read '" << path << "'");
  return parse_polynomial_model(text.str(), path);
}

}  // namespace kushner
