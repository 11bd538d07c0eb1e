// The keyword table of a LIGGGHTS style (keyword_table.h).
#include "keyword_table.h"

#include <cerrno>
#include <cstdlib>
#include <cstring>

namespace fdm {

namespace {

// the characters LIGGGHTS's force->numeric (floating = true) and force->inumeric accept
bool numberCharacters(const std::string &text, bool floating)
{
  if (text.empty()) return false;
  for (char c : text) {
    if (c >= '0' && c <= '9') continue;
    if (c == '-' || c == '+') continue;
    if (floating && (c == '.' || c == 'e' || c == 'E')) continue;
    return false;
  }
  return true;
}

}  // namespace

KeywordTable &KeywordTable::add(const std::string &key, int values, std::function<void(const std::string *)> set)
{
  entries_[key] = Entry{values, std::move(set)};
  return *this;
}

void KeywordTable::fail(const std::string &sentence) const
{
  throw KeywordError(owner_ + ": " + sentence);
}

std::string KeywordTable::alternatives(const std::vector<std::string> &names)
{
  std::string out;
  for (size_t k = 0; k < names.size(); k++) {
    if (k > 0) out += k + 1 == names.size() ? " or " : ", ";
    out += names[k];
  }
  return out;
}

double KeywordTable::toNumber(const std::string &key, const std::string &text) const
{
  char *end = nullptr;
  const double value = numberCharacters(text, true) ? std::strtod(text.c_str(), &end) : 0.0;
  if (!end || *end != '\0') fail(key + " needs a number, got " + text);
  return value;
}

long long KeywordTable::toInteger(const std::string &key, const std::string &text) const
{
  char *end = nullptr;
  errno = 0;
  const long long value = numberCharacters(text, false) ? std::strtoll(text.c_str(), &end, 10) : 0;
  if (!end || *end != '\0' || errno == ERANGE) fail(key + " needs an integer, got " + text);
  return value;
}

KeywordTable &KeywordTable::text(const std::string &key, std::string &out, const Rule<const std::string &> &rule)
{
  return add(key, 1, [this, rule, &out](const std::string *given) {
    if (rule.holds && !rule.holds(given[0])) fail(rule.sentence + ", got '" + given[0] + "'");
    out = given[0];
  });
}

KeywordTable &KeywordTable::number(const std::string &key, double &out, const Rule<double> &rule)
{
  return add(key, 1, [this, key, rule, &out](const std::string *given) {
    const double value = toNumber(key, given[0]);
    if (rule.holds && !rule.holds(value)) fail(rule.sentence + ", got " + given[0]);
    out = value;
  });
}

KeywordTable &KeywordTable::numbers(const std::string &key, int count, double *out)
{
  return add(key, count, [this, key, count, out](const std::string *given) {
    for (int k = 0; k < count; k++) out[k] = toNumber(key, given[k]);
  });
}

KeywordTable &KeywordTable::integer(const std::string &key, long long &out, const Rule<long long> &rule)
{
  return add(key, 1, [this, key, rule, &out](const std::string *given) {
    const long long value = toInteger(key, given[0]);
    if (rule.holds && !rule.holds(value)) fail(rule.sentence + ", got " + given[0]);
    out = value;
  });
}

KeywordTable &KeywordTable::yesNo(const std::string &key, bool &out)
{
  return choice<bool>(key, {{"yes", true}, {"no", false}}, out);
}

void KeywordTable::parse(const std::vector<std::string> &args, const std::string &seeAlso) const
{
  for (size_t i = 0; i < args.size();) {
    const std::string &key = args[i];
    const auto entry = entries_.find(key);
    if (entry == entries_.end()) fail("unknown keyword " + key + (seeAlso.empty() ? "" : " (" + seeAlso + ")"));
    const int n = entry->second.values;
    if (i + n >= args.size())
      fail("keyword " + key + " needs " + (n == 1 ? std::string("a value") : std::to_string(n) + " values"));
    entry->second.set(&args[i + 1]);
    i += 1 + n;
  }
}

}  // namespace fdm
