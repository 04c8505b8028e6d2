/* include/mpca.h on its own: compiled as C99 and as C++11 with every
 * warning an error (tests/tests/c_abi.rs, header_compiles_alone_*). */
#include "mpca.h"
