// The one translation unit that compiles Boost.JSON (header-only mode, Boost 1.81): every other file includes
// <boost/json.hpp> only. Do not include <boost/json/src.hpp> anywhere else (duplicate symbols).
#include <boost/json/src.hpp>
