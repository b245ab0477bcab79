#pragma once
// A registry of named models (materials, accelerations) filled at static
// initialisation: each model's file registers itself, so that adding a model
// touches no list elsewhere. `Model` has a `std::string_view name`.

#include <map>
#include <stdexcept>
#include <string_view>
#include <vector>

#include <fmt/format.h>

namespace outburst {

template <class Model>
class Registry {
 public:
  // Adds a model; two of one name are a programming error (std::logic_error,
  // `kind` names what they are in the message). Returns true, so that a
  // model's file can register from a constant's initialiser.
  // The name must outlive the program (a string literal): the registry keeps
  // a view of it.
  static bool add(const Model& model, std::string_view kind) {
    if (frozen())
      throw std::logic_error(fmt::format("{} \"{}\" registered after the list was taken", kind, model.name));
    if (!map().emplace(model.name, model).second)
      throw std::logic_error(fmt::format("two {} named \"{}\"", kind, model.name));
    return true;
  }
  // Every model, by name. The list is taken at the first call, after which a
  // registration is an error (it would be missing from the list): not to be
  // called during static initialisation.
  static const std::vector<Model>& all() {
    static const std::vector<Model> models = [] {
      frozen() = true;
      std::vector<Model> v;
      for (const auto& [name, model] : map()) v.push_back(model);
      return v;
    }();
    return models;
  }

 private:
  static bool& frozen() {
    static bool taken = false;
    return taken;
  }
  // A function's static: registrations from other files' initialisers may
  // run before any namespace-scope object of this file is constructed.
  static std::map<std::string_view, Model>& map() {
    static std::map<std::string_view, Model> models;
    return models;
  }
};

}  // namespace outburst
