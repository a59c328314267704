#pragma once
// Random byte-wise mutations of a valid input, for the fuzz tests of the readers (mesh files,
// checkpoints, time series): 1 to 4 of bit flips, inserted random bytes, deleted, duplicated and
// truncated ranges, a token (up to the next separator) replaced by an odd one, overwritten bytes.
#include <cstddef>
#include <random>
#include <string>
#include <vector>

namespace bendlab::test {

inline std::string mutate_bytes(const std::string& seed, std::mt19937_64& rng, const std::vector<std::string>& tokens,
                                const char* separators) {
  std::string s = seed;
  auto pick = [&](std::size_t n) { return n == 0 ? 0 : static_cast<std::size_t>(rng() % n); };
  const int mutations = 1 + static_cast<int>(rng() % 4);
  for (int m = 0; m < mutations; ++m) {
    switch (rng() % 7) {
      case 0:  // flip one bit
        if (!s.empty()) s[pick(s.size())] ^= static_cast<char>(1u << (rng() % 8));
        break;
      case 1:  // insert random bytes
        s.insert(pick(s.size() + 1), std::string(1 + pick(8), static_cast<char>(rng())));
        break;
      case 2: {  // delete a range
        const std::size_t at = pick(s.size()), n = 1 + pick(16);
        s.erase(at, n);
        break;
      }
      case 3: {  // duplicate a range
        const std::size_t at = pick(s.size()), n = 1 + pick(64);
        s.insert(pick(s.size() + 1), s.substr(at, n));
        break;
      }
      case 4:  // truncate
        s.resize(pick(s.size() + 1));
        break;
      case 5: {  // replace a token (up to the next separator) by an odd one
        const std::size_t at = pick(s.size());
        std::size_t end = s.find_first_of(separators, at);
        if (end == std::string::npos) end = s.size();
        s.replace(at, end - at, tokens[pick(tokens.size())]);
        break;
      }
      default:  // overwrite a byte with a random value
        if (!s.empty()) s[pick(s.size())] = static_cast<char>(rng());
    }
  }
  return s;
}

}  // namespace bendlab::test
