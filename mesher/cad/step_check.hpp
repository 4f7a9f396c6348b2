// A check of a STEP file's entity numbers before OpenCASCADE reads it (issue 14).
#pragma once

#include <string>
#include <string_view>

namespace hexfem {

// What is wrong with the entity numbers of the DATA section of a STEP file's text, or "" when
// nothing is: a number past 2^31 - 1 (OpenCASCADE's reader overflows it and crashes), a number
// run into letters or a point ("#1e999"), a '#' without a number, or a reference to an entity
// that is not defined (the translator dereferences the missing entity and crashes), or a number
// past 1e10 (shape healing crashes on such coordinates). Strings and comments are skipped, except
// that no entity number anywhere, in a string or not, may pass 2^31 - 1 (a lost quote makes
// OpenCASCADE read as an entity what looks like text here). Text without a DATA section gives ""
// (left to the reader).
std::string step_entity_problem(std::string_view text);

}  // namespace hexfem
