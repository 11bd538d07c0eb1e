/* The optional keywords of a LIGGGHTS style ("key value ..."), parsed once from a table: each keyword
   says how many values it takes, what they must be and where they go. Every message starts with the
   style's name and names the keyword and the value it got. No LIGGGHTS: the styles give it their
   arguments after the fixed ones, and turn a KeywordError into error->all.

   Numbers are read as LIGGGHTS's force->numeric and force->inumeric read them (the same characters
   accepted, the same conversion: strtod, strtol), so that a value means the same number as before. */

#ifndef FDM_KEYWORD_TABLE_H
#define FDM_KEYWORD_TABLE_H

#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace fdm {

class KeywordError : public std::invalid_argument {
 public:
  explicit KeywordError(const std::string &what) : std::invalid_argument(what) {}
};

class KeywordTable {
 public:
  // A rule a value must satisfy, and the sentence said when it does not (", got <value>" follows).
  template <class T>
  struct Rule {
    std::function<bool(T)> holds;
    std::string sentence;
  };

  explicit KeywordTable(std::string owner) : owner_(std::move(owner)) {}

  KeywordTable &text(const std::string &key, std::string &out, const Rule<const std::string &> &rule = {});
  KeywordTable &number(const std::string &key, double &out, const Rule<double> &rule = {});
  KeywordTable &numbers(const std::string &key, int count, double *out);
  KeywordTable &integer(const std::string &key, long long &out, const Rule<long long> &rule = {});
  KeywordTable &yesNo(const std::string &key, bool &out);
  // One of the named values; out takes the value paired with it.
  template <class T>
  KeywordTable &choice(const std::string &key, const std::vector<std::pair<std::string, T> > &values, T &out)
  {
    std::vector<std::string> names;
    for (const auto &v : values) names.push_back(v.first);
    return add(key, 1, [this, key, values, names, &out](const std::string *given) {
      for (const auto &v : values)
        if (v.first == given[0]) {
          out = v.second;
          return;
        }
      fail(key + " must be " + alternatives(names) + ", got " + given[0]);
    });
  }

  // A keyword of `count` values that `set` reads (with toNumber, toInteger, fail); a keyword given again
  // calls it again (e.g. one wall per "wall FACE ...").
  KeywordTable &values(const std::string &key, int count, std::function<void(const std::string *)> set)
  {
    return add(key, count, std::move(set));
  }

  // Reads args in order (key, then its values); throws KeywordError on an unknown keyword, a missing
  // or malformed value, or a value against its rule. seeAlso ends the unknown-keyword message.
  void parse(const std::vector<std::string> &args, const std::string &seeAlso) const;

  // "a", "a or b", "a, b or c"
  static std::string alternatives(const std::vector<std::string> &names);
  // LIGGGHTS's number forms: a floating-point number, an integer (KeywordError otherwise)
  double toNumber(const std::string &key, const std::string &text) const;
  long long toInteger(const std::string &key, const std::string &text) const;
  // Throws KeywordError: "<owner>: <sentence>"
  [[noreturn]] void fail(const std::string &sentence) const;

 private:
  struct Entry {
    int values;
    std::function<void(const std::string *)> set;
  };
  KeywordTable &add(const std::string &key, int values, std::function<void(const std::string *)> set);

  std::string owner_;
  std::map<std::string, Entry> entries_;
};

}  // namespace fdm

#endif
