// OpenBLAS maps one work buffer per thread (128 MiB of address space each in Debian 12's build:
// measured, a 134 221 824-byte mmap) the first time that thread runs, and when the mapping fails it
// retries forever. Under an address-space limit (ulimit -v, RLIMIT_AS, as batch schedulers set) a
// solve would hang in its factorization instead of failing: the paper's brick at n = 8 did so at
// 300 and 400 MB. So, where such a limit is set, the buffers are mapped at once, before anything
// large is allocated, and the memory checks that follow see them as used; where they cannot fit,
// the solve is refused (InputError) with the figures and the way out.
#pragma once

namespace contact3d {

// Maps OpenBLAS's buffers now (a matrix product on every thread) where RLIMIT_AS is set; throws
// InputError when the limit leaves no room for them. Nothing without a limit or without OpenBLAS.
void reserve_blas_buffers();

}  // namespace contact3d
