// graph_condition.cpp — the condition language (graph_condition.h): a tokenizer and a
// recursive-descent parser that emits RPN as it reduces, so no syntax tree is built.
#include "cooker/graph/graph_condition.h"

#include <charconv>
#include <cmath>

#include "cooker/json/json_check.h"

namespace ossa::cook {
namespace {

enum class Tok { End, Ident, Number, Op, Not, And, Or, LParen, RParen, True, False, Bad };

struct Token {
  Tok kind = Tok::End;
  size_t offset = 0;
  std::string_view text;
  double number = 0.0;
  CondOp op = CondOp::True;  // Tok::Op
};

bool ident_start(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
bool ident_char(char c) { return ident_start(c) || (c >= '0' && c <= '9'); }
bool digit(char c) { return c >= '0' && c <= '9'; }

const char* op_text(CondOp op) {
  switch (op) {
    case CondOp::Less: return "<";
    case CondOp::LessEqual: return "<=";
    case CondOp::Greater: return ">";
    case CondOp::GreaterEqual: return ">=";
    case CondOp::Equal: return "==";
    case CondOp::NotEqual: return "!=";
    default: return "?";
  }
}

class ConditionParser {
 public:
  ConditionParser(std::string_view text, std::span<const GraphParameter> parameters, const ParameterIndex* index,
                  bool hints)
      : s_(text), params_(parameters), index_(index), hints_(hints) {}

  ConditionResult run() {
    ConditionResult r;
    next();
    if (tok_.kind == Tok::End) {
      fail(0, "empty condition (leave \"when\" out for a transition that is always allowed)");
    } else if (parse_or() && tok_.kind != Tok::End) {
      if (tok_.kind == Tok::Bad) bad_token();
      else if (tok_.kind == Tok::RParen) fail(tok_.offset, "')' without a matching '('");
      else fail(tok_.offset, "expected '&&', '||' or the end of the condition, found '" + std::string(tok_.text) + "'");
    }
    if (error_.empty() && too_deep_at_ != 0)
      fail(too_deep_at_ - 1, "the condition holds more than " + std::to_string(kMaxConditionStack) +
                                 " values at once here (the runtime's limit): group fewer terms inside parentheses");
    r.ok = error_.empty();
    if (r.ok) r.code = std::move(code_);
    r.error = error_;
    r.error_offset = error_offset_;
    return r;
  }

 private:
  std::string_view s_;
  std::span<const GraphParameter> params_;
  const ParameterIndex* index_ = nullptr;
  bool hints_ = true;
  size_t i_ = 0;
  Token tok_;
  std::vector<CondInstr> code_;
  std::string error_;
  size_t error_offset_ = 0;
  int depth_ = 0;
  int stack_ = 0;           // values on the evaluation stack after the code so far
  size_t too_deep_at_ = 0;  // 1 + the offset where the stack first passed the limit; 0: never

  bool fail(size_t offset, std::string what) {
    if (error_.empty()) {
      error_ = std::move(what);
      error_offset_ = offset;
    }
    return false;
  }

  void next() {
    while (i_ < s_.size() && (s_[i_] == ' ' || s_[i_] == '\t' || s_[i_] == '\n' || s_[i_] == '\r')) ++i_;
    tok_ = Token{};
    tok_.offset = i_;
    if (i_ >= s_.size()) return;
    const char c = s_[i_];
    const auto two = [&](char second) { return i_ + 1 < s_.size() && s_[i_ + 1] == second; };
    const auto take = [&](Tok kind, size_t len) {
      tok_.kind = kind;
      tok_.text = s_.substr(i_, len);
      i_ += len;
    };
    const auto take_op = [&](CondOp op, size_t len) {
      take(Tok::Op, len);
      tok_.op = op;
    };
    if (ident_start(c)) {
      size_t k = i_;
      while (k < s_.size() && ident_char(s_[k])) ++k;
      const std::string_view word = s_.substr(i_, k - i_);
      Tok kind = Tok::Ident;
      if (word == "true") kind = Tok::True;
      else if (word == "false") kind = Tok::False;
      else if (word == "and") kind = Tok::And;
      else if (word == "or") kind = Tok::Or;
      else if (word == "not") kind = Tok::Not;
      take(kind, k - i_);
      return;
    }
    if (digit(c) ||
        ((c == '-' || c == '+' || c == '.') && i_ + 1 < s_.size() && (digit(s_[i_ + 1]) || s_[i_ + 1] == '.'))) {
      size_t k = i_;
      if (s_[k] == '-' || s_[k] == '+') ++k;
      while (k < s_.size() && (digit(s_[k]) || s_[k] == '.')) ++k;
      if (k < s_.size() && (s_[k] == 'e' || s_[k] == 'E')) {
        size_t e = k + 1;
        if (e < s_.size() && (s_[e] == '-' || s_[e] == '+')) ++e;
        if (e < s_.size() && digit(s_[e])) {
          k = e;
          while (k < s_.size() && digit(s_[k])) ++k;
        }
      }
      const size_t start = s_[i_] == '+' ? i_ + 1 : i_;
      double v = 0.0;
      const auto [ptr, ec] = std::from_chars(s_.data() + start, s_.data() + k, v);
      take(Tok::Number, k - i_);
      if (ec != std::errc() || ptr != s_.data() + k || !std::isfinite(v)) tok_.kind = Tok::Bad;
      tok_.number = v;
      return;
    }
    switch (c) {
      case '(': return take(Tok::LParen, 1);
      case ')': return take(Tok::RParen, 1);
      case '<': return two('=') ? take_op(CondOp::LessEqual, 2) : take_op(CondOp::Less, 1);
      case '>': return two('=') ? take_op(CondOp::GreaterEqual, 2) : take_op(CondOp::Greater, 1);
      case '=': return two('=') ? take_op(CondOp::Equal, 2) : take(Tok::Bad, 1);
      case '!': return two('=') ? take_op(CondOp::NotEqual, 2) : take(Tok::Not, 1);
      case '&': return two('&') ? take(Tok::And, 2) : take(Tok::Bad, 1);
      case '|': return two('|') ? take(Tok::Or, 2) : take(Tok::Bad, 1);
      default: break;
    }
    // One whole UTF-8 character, so the message quotes it intact.
    size_t len = 1;
    while (i_ + len < s_.size() && (static_cast<unsigned char>(s_[i_ + len]) & 0xC0u) == 0x80u) ++len;
    take(Tok::Bad, len);
  }

  /// Appends one instruction and follows the evaluation stack it needs (RPN: emission order is
  /// evaluation order): a loader runs conditions on a fixed stack of kMaxConditionStack values.
  void emit(CondOp op, uint16_t parameter = 0, float value = 0.0f) {
    code_.push_back({op, parameter, value});
    if (op == CondOp::And || op == CondOp::Or) --stack_;
    else if (op != CondOp::Not) ++stack_;
    if (stack_ > kMaxConditionStack && !too_deep_at_) too_deep_at_ = tok_.offset + 1;  // +1: 0 means "not yet"
  }

  bool bad_token() {
    if (tok_.text == "=") return fail(tok_.offset, "'=' is not an operator; compare with '=='");
    if (tok_.text == "&") return fail(tok_.offset, "'&' is not an operator; use '&&' (or 'and')");
    if (tok_.text == "|") return fail(tok_.offset, "'|' is not an operator; use '||' (or 'or')");
    if (tok_.kind == Tok::Bad && !tok_.text.empty() &&
        (digit(tok_.text[0]) || tok_.text[0] == '-' || tok_.text[0] == '.'))
      return fail(tok_.offset, "invalid number '" + std::string(tok_.text) + "'");
    return fail(tok_.offset, "unexpected '" + std::string(tok_.text) + "'");
  }

  bool parse_or() {
    if (!parse_and()) return false;
    while (tok_.kind == Tok::Or) {
      next();
      if (!parse_and()) return false;
      emit(CondOp::Or);
    }
    return true;
  }

  bool parse_and() {
    if (!parse_unary()) return false;
    while (tok_.kind == Tok::And) {
      next();
      if (!parse_unary()) return false;
      emit(CondOp::And);
    }
    return true;
  }

  bool parse_unary() {
    // Nesting is bounded by the text length, but a hostile "((((..." must not exhaust the stack.
    if (++depth_ > 256) return fail(tok_.offset, "condition nested too deeply");
    const bool ok = parse_unary_inner();
    --depth_;
    return ok;
  }

  bool parse_unary_inner() {
    switch (tok_.kind) {
      case Tok::Not:
        next();
        if (!parse_unary()) return false;
        emit(CondOp::Not);
        return true;
      case Tok::LParen: {
        const size_t open = tok_.offset;
        next();
        if (!parse_or()) return false;
        if (tok_.kind != Tok::RParen) {
          if (tok_.kind == Tok::End) return fail(open, "'(' is never closed");
          return fail(tok_.offset, "expected ')' or an operator, found '" + std::string(tok_.text) + "'");
        }
        next();
        return true;
      }
      case Tok::True:
        next();
        emit(CondOp::True);
        return true;
      case Tok::False:
        next();
        emit(CondOp::True);
        emit(CondOp::Not);
        return true;
      case Tok::Ident: return parse_atom();
      case Tok::End:
        return fail(tok_.offset, "the condition ends where a parameter, 'true', 'false', '!' or '(' was expected");
      case Tok::Bad: return bad_token();
      default:
        return fail(tok_.offset,
                    "expected a parameter, 'true', 'false', '!' or '(', found '" + std::string(tok_.text) + "'");
    }
  }

  int find_parameter(std::string_view name) const {
    if (index_ != nullptr) {
      const auto found = index_->find(name);
      return found == index_->end() ? -1 : found->second;
    }
    for (size_t p = 0; p < params_.size(); ++p)
      if (params_[p].name == name) return static_cast<int>(p);
    return -1;
  }

  bool parse_atom() {
    const Token name = tok_;
    const int index = find_parameter(name.text);
    if (index < 0) {
      if (!hints_) return fail(name.offset, "unknown parameter '" + std::string(name.text) + "'");
      std::string known;
      std::vector<std::string> names;
      for (const GraphParameter& p : params_) {
        if (names.size() < 20) known += (known.empty() ? "" : ", ") + p.name;
        names.push_back(p.name);
      }
      if (names.size() > 20) known += ", ... (" + std::to_string(names.size()) + " in all)";
      const std::string hint = json::closest_name(name.text, names);
      return fail(name.offset,
                  "unknown parameter '" + std::string(name.text) + "'" +
                      (hint.empty() ? "" : " (did you mean '" + hint + "'?)") +
                      (known.empty() ? "; the graph declares no \"parameters\"" : "; parameters: " + known));
    }
    const GraphParameter& param = params_[static_cast<size_t>(index)];
    const auto p16 = static_cast<uint16_t>(index);
    next();
    if (tok_.kind != Tok::Op) {
      if (tok_.kind == Tok::Bad && tok_.text == "=") return bad_token();
      switch (param.type) {
        case ParamType::Bool: emit(CondOp::Bool, p16); return true;
        case ParamType::Trigger: emit(CondOp::Trigger, p16); return true;
        case ParamType::Vector:
          return fail(name.offset, "'" + param.name + "' is a vector parameter: conditions cannot read it");
        case ParamType::Enum:
          return fail(name.offset, "'" + param.name + "' is an enum parameter: compare it with one of its values (" +
                                       param.name +
                                       " == " + (param.enum_values.empty() ? "value" : param.enum_values[0]) + ")");
        default:
          return fail(name.offset, "'" + param.name + "' is " + (param.type == ParamType::Int ? "an int" : "a float") +
                                       " parameter: compare it with a number (" + param.name + " > 0)");
      }
    }
    const Token op = tok_;
    next();
    const Token lit = tok_;
    const bool equality = op.op == CondOp::Equal || op.op == CondOp::NotEqual;
    switch (param.type) {
      case ParamType::Vector:
        return fail(name.offset, "'" + param.name + "' is a vector parameter: conditions cannot read it");
      case ParamType::Trigger:
        return fail(name.offset,
                    "'" + param.name + "' is a trigger: it cannot be compared, write it alone (" + param.name + ")");
      case ParamType::Float:
      case ParamType::Int:
        if (lit.kind != Tok::Number) {
          if (lit.kind == Tok::Bad) return bad_token();
          return fail(lit.offset, "'" + param.name + "' is " + (param.type == ParamType::Int ? "an int" : "a float") +
                                      " parameter: compare it with a number");
        }
        // A value past float's range would be stored as infinity, which no comparison can use.
        if (!(std::fabs(lit.number) <= 3.4028234663852886e38))
          return fail(lit.offset,
                      "the number " + std::string(lit.text) + " is outside the range of a float (+-3.4e38)");
        emit(op.op, p16, static_cast<float>(lit.number));
        next();
        return true;
      case ParamType::Bool:
        if (!equality)
          return fail(op.offset,
                      "'" + param.name + "' is a bool parameter: compare it only with == or != (or write it alone)");
        if (lit.kind != Tok::True && lit.kind != Tok::False)
          return fail(lit.offset, "'" + param.name + "' is a bool parameter: compare it with true or false");
        emit(op.op, p16, lit.kind == Tok::True ? 1.0f : 0.0f);
        next();
        return true;
      case ParamType::Enum: {
        std::string values;
        for (const std::string& v : param.enum_values) values += (values.empty() ? "" : ", ") + v;
        if (!equality)
          return fail(op.offset, "'" + param.name + "' is an enum parameter: compare it only with == or !=, not " +
                                     op_text(op.op));
        if (lit.kind != Tok::Ident)
          return fail(lit.offset,
                      "'" + param.name + "' is an enum parameter: compare it with one of its values (" + values + ")");
        for (size_t v = 0; v < param.enum_values.size(); ++v) {
          if (param.enum_values[v] == lit.text) {
            emit(op.op, p16, static_cast<float>(v));
            next();
            return true;
          }
        }
        return fail(lit.offset, "'" + std::string(lit.text) + "' is not a value of enum '" + param.name +
                                    "' (values: " + values + ")");
      }
    }
    return fail(name.offset, std::string("parameter of unknown type ") + type_word(param.type));
  }
};

}  // namespace

const char* type_word(ParamType t) {
  switch (t) {
    case ParamType::Float: return "float";
    case ParamType::Int: return "int";
    case ParamType::Bool: return "bool";
    case ParamType::Enum: return "enum";
    case ParamType::Trigger: return "trigger";
    case ParamType::Vector: return "vector";
  }
  return "?";
}

ConditionResult compile_condition(std::string_view text, std::span<const GraphParameter> parameters,
                                  const ParameterIndex* index, bool hints) {
  return ConditionParser(text, parameters, index, hints).run();
}

bool is_condition_identifier(std::string_view name) {
  if (name.empty() || !ident_start(name[0])) return false;
  for (char c : name)
    if (!ident_char(c)) return false;
  return name != "true" && name != "false" && name != "and" && name != "or" && name != "not";
}

}  // namespace ossa::cook
