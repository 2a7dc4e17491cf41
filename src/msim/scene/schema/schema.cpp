#include "msim/scene/schema/schema.hpp"

#include <stdexcept>

namespace msim::scene {

Schema::Schema(SchemaType type, std::string description) : type_(type), description_(std::move(description)) {}

Schema Schema::object(std::string description) { return Schema(SchemaType::Object, std::move(description)); }

Schema Schema::array(Schema item, std::string description) {
  Schema s(SchemaType::Array, std::move(description));
  s.item_ = std::make_shared<Schema>(std::move(item));
  s.default_ = json::array();
  return s;
}

Schema Schema::variant(std::string description) {
  // A variant has no natural default (which alternative?), so it starts required.
  Schema s(SchemaType::Variant, std::move(description));
  s.required_ = true;
  return s;
}

// Builder misuse is a bug in msim, not bad user input, hence logic_error.
void Schema::expect(SchemaType wanted, const char* what) const {
  if (type_ != wanted) throw std::logic_error(std::string("Schema::") + what + " used on a schema of the wrong type");
}

Schema& Schema::addField(std::string name, Schema schema) {
  expect(SchemaType::Object, "field");
  if (findField(name)) throw std::logic_error("Schema field '" + name + "' declared twice");
  fields_.push_back({std::move(name), std::make_shared<Schema>(std::move(schema))});
  return *fields_.back().schema;
}

Schema& Schema::number(std::string name, std::string unit, double defaultValue, std::string description) {
  Schema s(SchemaType::Number, std::move(description));
  s.unit_ = std::move(unit);
  s.default_ = defaultValue;
  return addField(std::move(name), std::move(s));
}

Schema& Schema::number(std::string name, std::string unit, std::string description) {
  Schema s(SchemaType::Number, std::move(description));
  s.unit_ = std::move(unit);
  s.required_ = true;
  return addField(std::move(name), std::move(s));
}

Schema& Schema::integer(std::string name, long long defaultValue, std::string description) {
  Schema s(SchemaType::Integer, std::move(description));
  s.default_ = defaultValue;
  return addField(std::move(name), std::move(s));
}

Schema& Schema::integer(std::string name, std::string description) {
  Schema s(SchemaType::Integer, std::move(description));
  s.required_ = true;
  return addField(std::move(name), std::move(s));
}

Schema& Schema::boolean(std::string name, bool defaultValue, std::string description) {
  Schema s(SchemaType::Bool, std::move(description));
  s.default_ = defaultValue;
  return addField(std::move(name), std::move(s));
}

Schema& Schema::string(std::string name, std::string defaultValue, std::string description) {
  Schema s(SchemaType::String, std::move(description));
  s.default_ = std::move(defaultValue);
  return addField(std::move(name), std::move(s));
}

Schema& Schema::string(std::string name, std::string description) {
  Schema s(SchemaType::String, std::move(description));
  s.required_ = true;
  return addField(std::move(name), std::move(s));
}

Schema Schema::vectorItem(std::string unit, int length, std::string description) {
  Schema s(SchemaType::Vector, std::move(description));
  s.unit_ = std::move(unit);
  s.lengths_ = {length};
  s.required_ = true;
  return s;
}

Schema& Schema::vector(std::string name, std::string unit, std::vector<double> defaultValue, std::string description) {
  Schema s(SchemaType::Vector, std::move(description));
  s.unit_ = std::move(unit);
  s.lengths_ = {static_cast<int>(defaultValue.size())};
  s.default_ = std::move(defaultValue);
  return addField(std::move(name), std::move(s));
}

Schema& Schema::vector(std::string name, std::string unit, int length, std::string description) {
  Schema s(SchemaType::Vector, std::move(description));
  s.unit_ = std::move(unit);
  s.lengths_ = {length};
  s.required_ = true;
  return addField(std::move(name), std::move(s));
}

Schema& Schema::array(std::string name, Schema item, std::string description) {
  return addField(std::move(name), Schema::array(std::move(item), std::move(description)));
}

Schema& Schema::field(std::string name, Schema schema) { return addField(std::move(name), std::move(schema)); }

Schema& Schema::alternative(std::string typeName, Schema objectSchema) {
  expect(SchemaType::Variant, "alternative");
  objectSchema.expect(SchemaType::Object, "alternative (its schema must be an object)");
  if (objectSchema.findField(kVariantTypeKey))
    throw std::logic_error("variant alternative '" + typeName + "' must not declare its own 'type' field");
  alternatives_.push_back({std::move(typeName), std::make_shared<Schema>(std::move(objectSchema))});
  return *this;
}

Schema& Schema::min(double value, Bound kind) {
  if (type_ != SchemaType::Number && type_ != SchemaType::Integer && type_ != SchemaType::Vector)
    throw std::logic_error("Schema::min used on a non-numeric schema");
  lower_ = NumericBound{value, kind};
  return *this;
}

Schema& Schema::max(double value, Bound kind) {
  if (type_ != SchemaType::Number && type_ != SchemaType::Integer && type_ != SchemaType::Vector)
    throw std::logic_error("Schema::max used on a non-numeric schema");
  upper_ = NumericBound{value, kind};
  return *this;
}

Schema& Schema::choices(std::vector<std::string> allowed) {
  expect(SchemaType::String, "choices");
  choices_ = std::move(allowed);
  return *this;
}

Schema& Schema::lengths(std::vector<int> allowed) {
  expect(SchemaType::Vector, "lengths");
  lengths_ = std::move(allowed);
  return *this;
}

Schema& Schema::items(int minItems, int maxItems) {
  expect(SchemaType::Array, "items");
  minItems_ = minItems;
  maxItems_ = maxItems;
  return *this;
}

Schema& Schema::required() {
  required_ = true;
  default_.reset();
  return *this;
}

Schema& Schema::defaultValue(json value) {
  required_ = false;
  default_ = std::move(value);
  return *this;
}

const SchemaField* Schema::findField(std::string_view name) const {
  for (const auto& f : fields_)
    if (f.name == name) return &f;
  return nullptr;
}

const SchemaAlternative* Schema::findAlternative(std::string_view typeName) const {
  for (const auto& a : alternatives_)
    if (a.typeName == typeName) return &a;
  return nullptr;
}

}  // namespace msim::scene
