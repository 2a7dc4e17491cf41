#pragma once
// Schema: the declared shape of a scene file. Every parameter carries its type, default, SI unit,
// description and allowed range, so one declaration drives validation (resolve), `msim info`
// (describe) and the generated docs (markdownReference).
//
// Phenomena declare parameters with chained builder calls:
//   Schema gas = Schema::object("gas phenomenon");
//   gas.number("dx", "m", 0.1, "cell size").min(0, Bound::Exclusive);
//   gas.integer("resolution", 64, "cells along the longest axis").min(1);
//   gas.array("sources", sourceSchema, "gas emitters");
// Field builders return the new field's schema so range/choice modifiers can follow. Child nodes
// live on the heap, so a returned reference stays valid while more fields are added; copies of a
// Schema share their children, which is fine because a schema is read-only once declared.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace msim::scene {

using json = nlohmann::json;

enum class SchemaType { Object, Array, Number, Integer, Bool, String, Vector, Variant };
enum class Bound { Inclusive, Exclusive };

class Schema;

struct SchemaField {
  std::string name;
  std::shared_ptr<Schema> schema;
};

// One choice of a Variant: the value of its "type" key and the object schema it selects.
struct SchemaAlternative {
  std::string typeName;
  std::shared_ptr<Schema> schema;
};

struct NumericBound {
  double value;
  Bound kind;
};

class Schema {
 public:
  static Schema object(std::string description = {});
  static Schema array(Schema item, std::string description = {});
  // An object whose "type" key picks one of the alternatives added with alternative().
  static Schema variant(std::string description = {});
  // A fixed-length vector of numbers on its own, e.g. the item of an array of polygon vertices.
  static Schema vectorItem(std::string unit, int length, std::string description = {});

  // ---- Object builders: add a field and return its schema. Overloads without a default make
  // the field required.
  Schema& number(std::string name, std::string unit, double defaultValue, std::string description);
  Schema& number(std::string name, std::string unit, std::string description);
  Schema& integer(std::string name, long long defaultValue, std::string description);
  Schema& integer(std::string name, std::string description);
  Schema& boolean(std::string name, bool defaultValue, std::string description);
  Schema& string(std::string name, std::string defaultValue, std::string description);
  Schema& string(std::string name, std::string description);
  // Fixed-length vector of numbers; the default fixes the length (change it with lengths()).
  Schema& vector(std::string name, std::string unit, std::vector<double> defaultValue, std::string description);
  Schema& vector(std::string name, std::string unit, int length, std::string description);
  Schema& array(std::string name, Schema item, std::string description);
  // Any prebuilt schema (sub-object, variant, ...) as a field.
  Schema& field(std::string name, Schema schema);

  // ---- Variant builder.
  Schema& alternative(std::string typeName, Schema objectSchema);

  // ---- Modifiers (return *this for chaining).
  Schema& min(double value, Bound kind = Bound::Inclusive);  // Number, Integer, Vector components
  Schema& max(double value, Bound kind = Bound::Inclusive);
  Schema& choices(std::vector<std::string> allowed);   // String
  Schema& lengths(std::vector<int> allowed);           // Vector: e.g. {2, 3} for 2D or 3D scenes
  Schema& items(int minItems, int maxItems = -1);      // Array: -1 = unbounded
  Schema& required();                                  // drop the default: the key must be given
  Schema& defaultValue(json value);

  // ---- Read access for resolve/describe.
  SchemaType type() const { return type_; }
  const std::string& description() const { return description_; }
  const std::string& unit() const { return unit_; }
  bool isRequired() const { return required_; }
  const std::optional<json>& defaultJson() const { return default_; }
  const std::optional<NumericBound>& lowerBound() const { return lower_; }
  const std::optional<NumericBound>& upperBound() const { return upper_; }
  const std::vector<std::string>& allowedStrings() const { return choices_; }
  const std::vector<int>& allowedLengths() const { return lengths_; }
  int minItems() const { return minItems_; }
  int maxItems() const { return maxItems_; }
  const std::vector<SchemaField>& fields() const { return fields_; }
  const SchemaField* findField(std::string_view name) const;
  const Schema& itemSchema() const { return *item_; }
  const std::vector<SchemaAlternative>& alternatives() const { return alternatives_; }
  const SchemaAlternative* findAlternative(std::string_view typeName) const;

 private:
  explicit Schema(SchemaType type, std::string description = {});
  Schema& addField(std::string name, Schema schema);
  void expect(SchemaType wanted, const char* what) const;

  SchemaType type_;
  std::string description_;
  std::string unit_;
  bool required_ = false;
  std::optional<json> default_;
  std::optional<NumericBound> lower_;
  std::optional<NumericBound> upper_;
  std::vector<std::string> choices_;
  std::vector<int> lengths_;
  int minItems_ = 0;
  int maxItems_ = -1;
  std::vector<SchemaField> fields_;
  std::shared_ptr<Schema> item_;
  std::vector<SchemaAlternative> alternatives_;
};

// Key of a Variant object that selects its alternative.
inline constexpr const char* kVariantTypeKey = "type";

}  // namespace msim::scene
