// SPDX-License-Identifier: Apache-2.0
// Compiles the public API as C++: every declaration must be valid there too.
#include "umbra/io.h"

int umbra_header_compiles_as_cxx();
int umbra_header_compiles_as_cxx() { return static_cast<int>(UMBRA_SUCCESS); }
