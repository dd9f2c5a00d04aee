// The product M1 x M2 x ... of manifolds (spec: "Constrained systems, S2 and products"): a point is
// the factors' points concatenated in order, and so are tangent vectors, velocities and momenta.
// The factors are its parts (abi/plugin_object.hpp, Part): manifold objects the host makes from
// "factors" and passes in. Every operation is the factors' own on their blocks: the natural chart
// of a product of Lie groups is the product of the factors' natural charts (q0 exp(xi) taken
// componentwise), so its derivatives are block diagonal in the factors' variables, and so are the
// generators of the group's action. R^n is a Lie group under addition (q exp(xi) = q + xi), so a
// product of vector spaces and Lie groups is a Lie group. A product of vector spaces and manifolds
// served in their embeddings (S2: Manifold::defining_constraint) is served in its embedding too,
// with the factors' equations as its own (each factor's rows on its block of the point); it
// declares the structure of a homogeneous space (of the product of the factors' groups). With any
// other mixture the product declares the structure `product`, which the constructions refuse.
#include <algorithm>
#include <climits>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "varia/abi/constraint.hpp"
#include "varia/abi/manifold.hpp"
#include "varia/sdk/plugin.hpp"

namespace {

using varia::Derivatives;
using varia::Jet2;
using varia::Manifold;
using varia::ManifoldStructure;
using varia::Status;

// A factor with where its numbers sit in the product's: its point at point_offset, its tangent
// vectors at offset.
struct Factor {
  Manifold* manifold = nullptr;
  int point_size = 0, dim = 0, point_offset = 0, offset = 0;
};

// Derivatives of k components in V variables, a factor's, scattered into the product's: factor
// component c is product component component_offset + c, factor variable j is variable(j).
template <class Variable>
void scatter(const Derivatives& from, const Derivatives& to, int k, int V, int component_offset, long product_V,
             Variable variable) {
  for (int c = 0; c < k; ++c) {
    const long pc = component_offset + c;
    if (to.value != nullptr) to.value[pc] = from.value[c];
    for (int a = 0; a < V && to.gradient != nullptr; ++a) to.gradient[pc * product_V + variable(a)] = from.gradient[c * V + a];
    for (int a = 0; a < V && to.hessian != nullptr; ++a)
      for (int b = 0; b < V; ++b)
        to.hessian[(pc * product_V + variable(a)) * product_V + variable(b)] = from.hessian[(static_cast<long>(c) * V + a) * V + b];
  }
}

// Buffers for a factor's derivatives of k components in V variables, where `like` asks for them.
struct DerivativeBuffers {
  std::vector<double> value, gradient, hessian;
  Derivatives sized(const Derivatives& like, int k, int V) {
    value.resize(static_cast<std::size_t>(k));
    gradient.resize(like.gradient != nullptr ? static_cast<std::size_t>(k) * V : 0);
    hessian.resize(like.hessian != nullptr ? static_cast<std::size_t>(k) * V * V : 0);
    return Derivatives{value.data(), like.gradient != nullptr ? gradient.data() : nullptr,
                       like.hessian != nullptr ? hessian.data() : nullptr};
  }
};

void zero(const Derivatives& d, long k, long V) {
  if (d.gradient != nullptr) std::fill_n(d.gradient, k * V, 0.0);
  if (d.hessian != nullptr) std::fill_n(d.hessian, k * V * V, 0.0);
}

// The product's equations: each embedded factor's defining constraint on its block of the point,
// its rows after the previous factors' rows. Bound by the host to the product's point_size().
class ProductEquations final : public varia::Constraint {
 public:
  void add(varia::Constraint* equations, int point_offset, int point_size) {
    blocks_.push_back(Block{equations, point_offset, point_size});
  }
  bool empty() const { return blocks_.empty(); }
  Status bind(int n, int /*space_dim*/) noexcept override {
    return varia::sdk::guarded(error_, [&] {
      rows_ = 0;
      jacobian_rows_.clear();
      jacobian_cols_.clear();
      hessian_rows_.clear();
      hessian_cols_.clear();
      for (std::size_t i = 0; i < blocks_.size(); ++i) {
        Block& b = blocks_[i];
        if (b.point_offset + b.point_size > n) throw std::invalid_argument("the product's point has fewer numbers");
        if (Status s = b.equations->bind(b.point_size, 0))
          throw std::invalid_argument("factor " + std::to_string(i) + ": " + s);
        b.first_row = rows_;
        b.jacobian_first = static_cast<int>(jacobian_rows_.size());
        b.hessian_first = static_cast<int>(hessian_rows_.size());
        const int *r = nullptr, *c = nullptr;
        b.jacobian_entries = b.equations->jacobian_pattern(&r, &c);
        for (int e = 0; e < b.jacobian_entries; ++e) {
          jacobian_rows_.push_back(b.first_row + r[e]);
          jacobian_cols_.push_back(b.point_offset + c[e]);
        }
        b.hessian_entries = b.equations->hessian_pattern(&r, &c);
        for (int e = 0; e < b.hessian_entries; ++e) {
          hessian_rows_.push_back(b.point_offset + r[e]);
          hessian_cols_.push_back(b.point_offset + c[e]);
        }
        rows_ += b.equations->size();
      }
    });
  }
  int size() const noexcept override { return rows_; }
  int jacobian_pattern(const int** rows, const int** cols) const noexcept override {
    *rows = jacobian_rows_.data();
    *cols = jacobian_cols_.data();
    return static_cast<int>(jacobian_rows_.size());
  }
  int hessian_pattern(const int** rows, const int** cols) const noexcept override {
    *rows = hessian_rows_.data();
    *cols = hessian_cols_.data();
    return static_cast<int>(hessian_rows_.size());
  }
  Status evaluate(const double* q, double* g, double* jacobian) noexcept override {
    return each([&](const Block& b) {
      return b.equations->evaluate(q + b.point_offset, g != nullptr ? g + b.first_row : nullptr,
                                   jacobian != nullptr ? jacobian + b.jacobian_first : nullptr);
    });
  }
  bool quadratic() const noexcept override {
    return std::all_of(blocks_.begin(), blocks_.end(), [](const Block& b) { return b.equations->quadratic(); });
  }
  Status weighted_hessian(const double* q, const double* lambda, double* values) noexcept override {
    return each([&](const Block& b) {
      return b.equations->weighted_hessian(q + b.point_offset, lambda + b.first_row, values + b.hessian_first);
    });
  }

 private:
  struct Block {
    varia::Constraint* equations;
    int point_offset, point_size;
    int first_row = 0, jacobian_first = 0, hessian_first = 0, jacobian_entries = 0, hessian_entries = 0;
  };
  template <class Call>
  Status each(Call call) noexcept {
    for (const Block& b : blocks_)
      if (Status s = call(b)) {
        error_ = s;
        return error_.c_str();
      }
    return nullptr;
  }
  std::vector<Block> blocks_;
  int rows_ = 0;
  std::vector<int> jacobian_rows_, jacobian_cols_, hessian_rows_, hessian_cols_;
  std::string error_;
};

class Product final : public Manifold {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"json({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {
      "factors": {"type": "array", "minItems": 1, "x-varia-part": "manifold",
                  "description": "the factors M1, M2, ..., each a manifold object",
                  "items": {"type": "object", "required": ["type"],
                            "properties": {"type": {"type": "string", "minLength": 1}}}}
    },
    "required": ["factors"],
    "additionalProperties": false
  })json";
  static constexpr const char* properties = R"json({
    "group": "the product of the factors' groups, componentwise (R^n under addition)",
    "chart": "the product of the factors' natural charts",
    "point": "the factors' points, concatenated in order",
    "tangent": "the factors' tangent vectors, concatenated in order"
  })json";

  Product(const nlohmann::json& parameters, const varia::sdk::Context& context) {
    const auto manifolds = context.parts_of<Manifold>("factors", varia::Kind::manifold);
    if (manifolds.empty() || manifolds.size() != parameters.at("factors").size())
      throw std::runtime_error("product: its factors are manifold objects that the host makes from \"factors\"; it "
                               "was given " + std::to_string(manifolds.size()));
    long point_size = 0, dim = 0;
    for (Manifold* manifold : manifolds) {
      factors_.push_back(Factor{manifold, manifold->point_size(), manifold->dim(), static_cast<int>(point_size),
                                static_cast<int>(dim)});
      point_size += manifold->point_size();
      dim += manifold->dim();
      if (point_size > INT_MAX)
        throw std::invalid_argument("factors: the product's points would have more than 2^31 - 1 numbers");
    }
    point_size_ = static_cast<int>(point_size);
    dim_ = static_cast<int>(dim);
    structure_ = structure_of(manifolds);
    if (structure_ == ManifoldStructure::homogeneous_space)
      for (const Factor& f : factors_)
        if (varia::Constraint* equations = f.manifold->defining_constraint())
          equations_.add(equations, f.point_offset, f.point_size);
  }

  int point_size() const noexcept override { return point_size_; }
  int dim() const noexcept override { return dim_; }
  ManifoldStructure structure() const noexcept override { return structure_; }
  varia::Constraint* defining_constraint() noexcept override { return equations_.empty() ? nullptr : &equations_; }

  Status retract(const double* q0, const double* xi, double* q) noexcept override {
    return each([&](const Factor& f) {
      return f.manifold->retract(q0 + f.point_offset, xi + f.offset, q + f.point_offset);
    });
  }
  Status local(const double* q0, const double* q, double* xi) noexcept override {
    return each([&](const Factor& f) {
      return f.manifold->local(q0 + f.point_offset, q + f.point_offset, xi + f.offset);
    });
  }
  bool contains(const double* q, char* why, int why_size) noexcept override {
    for (std::size_t i = 0; i < factors_.size(); ++i) {
      char reason[200] = {};
      if (factors_[i].manifold->contains(q + factors_[i].point_offset, reason, sizeof reason)) continue;
      if (why != nullptr && why_size > 0)
        std::snprintf(why, static_cast<std::size_t>(why_size), "factor %zu: %s", i, reason);
      return false;
    }
    return true;
  }
  // The largest of the factors' distances from their embeddings' constraints.
  double constraint_error(const double* q) const noexcept override {
    double largest = 0.0;
    for (const Factor& f : factors_) largest = std::max(largest, f.manifold->constraint_error(q + f.point_offset));
    return largest;
  }
  bool has_constraint() const noexcept override {
    return std::any_of(factors_.begin(), factors_.end(), [](const Factor& f) { return f.manifold->has_constraint(); });
  }

  // Factor f's variables (eta_f, xi_f) are the product's (eta, xi) at its offset in each half.
  Status chart(const double* q0, const double* xi, const double* xi_dot, Derivatives point,
               Derivatives velocity) noexcept override {
    const long V = 2L * dim_;
    zero(point, point_size_, V);
    zero(velocity, dim_, V);
    return each([&](const Factor& f) -> Status {
      const int Vf = 2 * f.dim;
      const Derivatives fp = point_buffers_.sized(point, f.point_size, Vf);
      const Derivatives fv = velocity_buffers_.sized(velocity, f.dim, Vf);
      if (Status s = f.manifold->chart(q0 + f.point_offset, xi + f.offset, xi_dot + f.offset, fp, fv)) return s;
      const auto variable = [&](int j) { return j < f.dim ? f.offset + j : dim_ + f.offset + (j - f.dim); };
      if (point.value != nullptr || point.gradient != nullptr || point.hessian != nullptr)
        scatter(fp, point, f.point_size, Vf, f.point_offset, V, variable);
      if (velocity.value != nullptr || velocity.gradient != nullptr || velocity.hessian != nullptr)
        scatter(fv, velocity, f.dim, Vf, f.offset, V, variable);
      return nullptr;
    });
  }
  Status local_derivatives(const double* q0, const double* q, Derivatives xi) noexcept override {
    zero(xi, dim_, point_size_);
    return each([&](const Factor& f) -> Status {
      const Derivatives fx = point_buffers_.sized(xi, f.dim, f.point_size);
      if (Status s = f.manifold->local_derivatives(q0 + f.point_offset, q + f.point_offset, fx)) return s;
      scatter(fx, xi, f.dim, f.point_size, f.offset, point_size_, [&](int j) { return f.point_offset + j; });
      return nullptr;
    });
  }

  // On a vector-space factor the increment q0 + xi - q0 is xi, exactly.
  bool has_increment() const noexcept override {
    return std::all_of(factors_.begin(), factors_.end(), [](const Factor& f) {
      return f.manifold->structure() == ManifoldStructure::vector_space || f.manifold->has_increment();
    });
  }
  Status increment(const double* q0, const double* xi, double* dq, double* dq_low) noexcept override {
    return each([&](const Factor& f) -> Status {
      if (f.manifold->structure() != ManifoldStructure::vector_space)
        return f.manifold->increment(q0 + f.point_offset, xi + f.offset, dq + f.point_offset, dq_low + f.point_offset);
      std::copy_n(xi + f.offset, f.dim, dq + f.point_offset);
      std::fill_n(dq_low + f.point_offset, f.dim, 0.0);
      return nullptr;
    });
  }

  Status translate(const Jet2* q, const Jet2* xi, Jet2* moved) noexcept override {
    return each([&](const Factor& f) -> Status {
      if (f.manifold->structure() != ManifoldStructure::vector_space)
        return f.manifold->translate(q + f.point_offset, xi + f.offset, moved + f.point_offset);
      for (int i = 0; i < f.dim; ++i) moved[f.point_offset + i] = q[f.point_offset + i] + xi[f.offset + i];
      return nullptr;
    });
  }
  // D(q) is block diagonal: factor f's generators in its rows and columns, the identity on a
  // vector space.
  Status generators(const Jet2* q, Jet2* D) noexcept override {
    return guarded([&] {
      std::fill_n(D, static_cast<long>(point_size_) * dim_, Jet2(0.0));
      for (const Factor& f : factors_) {
        const long m = f.point_size, n = f.dim;
        if (f.manifold->structure() == ManifoldStructure::vector_space) {
          for (long i = 0; i < n; ++i) D[(f.point_offset + i) * dim_ + f.offset + i] = Jet2(1.0);
          continue;
        }
        block_.resize(static_cast<std::size_t>(m * n));
        varia::check(*f.manifold, f.manifold->generators(q + f.point_offset, block_.data()), "generators");
        for (long k = 0; k < m; ++k)
          for (long a = 0; a < n; ++a) D[(f.point_offset + k) * dim_ + f.offset + a] = block_[k * n + a];
      }
    });
  }

 private:
  // Vector spaces and Lie groups: a Lie group (a vector space if all are); vector spaces and
  // embedded manifolds: served in the embedding, a homogeneous space; otherwise `product`.
  static ManifoldStructure structure_of(const std::vector<Manifold*>& manifolds) {
    int vector_spaces = 0, groups = 0, embedded = 0;
    for (Manifold* manifold : manifolds) {
      const ManifoldStructure s = manifold->structure();
      if (s == ManifoldStructure::vector_space) ++vector_spaces;
      else if (s == ManifoldStructure::lie_group) ++groups;
      else if (manifold->defining_constraint() != nullptr) ++embedded;
    }
    const int count = static_cast<int>(manifolds.size());
    if (vector_spaces == count) return ManifoldStructure::vector_space;
    if (vector_spaces + groups == count) return ManifoldStructure::lie_group;
    if (vector_spaces + embedded == count) return ManifoldStructure::homogeneous_space;
    return ManifoldStructure::product;
  }
  // Runs the factors' call in turn; the first failure, with the factor it came from.
  template <class Call>
  Status each(Call call) noexcept {
    for (std::size_t i = 0; i < factors_.size(); ++i)
      if (Status s = call(factors_[i])) {
        error_ = "factor " + std::to_string(i) + ": " + s;
        return error_.c_str();
      }
    return nullptr;
  }
  template <class F>
  Status guarded(F&& f) noexcept {
    return varia::sdk::guarded(error_, std::forward<F>(f));
  }

  std::vector<Factor> factors_;
  int point_size_ = 0, dim_ = 0;
  ManifoldStructure structure_ = ManifoldStructure::product;
  ProductEquations equations_;
  DerivativeBuffers point_buffers_, velocity_buffers_;
  std::vector<Jet2> block_;
  std::string error_;
};

}  // namespace

VARIA_PLUGIN(Product, manifold, product)
