// Large blocks on huge pages (huge_pages.cpp): whether this build's operator new advises them.
#pragma once

namespace hemotree {

// False where the global operator new and delete are left as they are (under
// AddressSanitizer, whose own pair checks that they match).
bool advises_huge_pages();

}  // namespace hemotree
