// graph_condition.h — a transition's "when" text compiled into the RPN the runtime evaluates.
//
// Grammar (docs/GRAPH.md, "Conditions"):
//   or    := and (('||' | 'or') and)*
//   and   := unary (('&&' | 'and') unary)*
//   unary := ('!' | 'not') unary | '(' or ')' | atom
//   atom  := 'true' | 'false' | IDENT | IDENT OP literal        OP: < <= > >= == !=
//   literal := number | 'true' | 'false' | an enum value's name
// A bare bool parameter reads as Bool, a bare trigger as Trigger; floats and ints compare with
// numbers, bools with true/false (== / != only), enums with one of their values' names (== / !=
// only, stored as the value's index); a trigger cannot be compared, and a bare float, int or
// enum is a type error. Output is RPN for the stack machine of format/ossa.fbs ConditionOp:
// operands first, operators after, And/Or left-associative, so `a || b && c` is `a b c And Or`.
//
// Separate from graph_compile.cpp because it is a language of its own, with its own tests.
#pragma once
#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "cooker/model/graph_def.h"

namespace ossa::cook {

/// "float", "int", "bool", "enum", "trigger": a parameter type as the JSON writes it.
const char* type_word(ParamType t);

struct ConditionResult {
  bool ok = false;
  std::vector<CondInstr> code;  // RPN, never empty when ok ("true" is [True])
  size_t error_offset = 0;      // byte offset into the text where the error is
  std::string error;            // what is wrong, without a position
};

/// The deepest evaluation stack a condition may need: the loader's limit (validate_graph.cpp).
inline constexpr int kMaxConditionStack = 16;

/// The parameters' indices by name, for compile_condition (a graph compiles thousands of
/// conditions against thousands of parameters).
using ParameterIndex = std::unordered_map<std::string_view, int>;

/// Compiles `text` against the graph's parameters, found through `index` when given (else by a
/// scan). `hints` false: an unknown parameter's message names it without searching the
/// parameters for a near name or listing them (the caller keeps no more messages). O(text length)
/// with an index, O(text length * parameters) without.
ConditionResult compile_condition(std::string_view text, std::span<const GraphParameter> parameters,
                                  const ParameterIndex* index = nullptr, bool hints = true);

/// True when `name` can be written in a condition: [A-Za-z_][A-Za-z0-9_]* and not one of the
/// words true, false, and, or, not.
bool is_condition_identifier(std::string_view name);

}  // namespace ossa::cook
