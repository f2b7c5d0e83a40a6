//! Runtime selection of wider vector instructions for the few hot kernels.
//!
//! The workspace builds for baseline x86-64 (SSE2). [`multiversion!`] compiles a kernel a
//! second time with AVX2 + FMA (and a third with AVX-512) enabled and picks the widest version
//! the CPU supports, once per call (the feature test is a cached load). Rust never contracts
//! `a*b + c` into a fused multiply-add on its own, explicit `mul_add` is exactly rounded in
//! every version (an instruction with FMA, the C library's `fma` without), and the kernels
//! keep a fixed summation order, so every version returns bit-identical results: the choice
//! affects speed only.

/// Defines `fn $name(args) -> ret` dispatching to AVX-512/AVX2/baseline builds of `$body`.
macro_rules! multiversion {
    ($(#[$meta:meta])* $vis:vis fn $name:ident($($arg:ident : $ty:ty),* $(,)?) $(-> $ret:ty)? $body:block) => {
        $(#[$meta])*
        $vis fn $name($($arg: $ty),*) $(-> $ret)? {
            #[inline(always)]
            fn inner($($arg: $ty),*) $(-> $ret)? $body
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx512f,avx2,fma")]
                fn wide512($($arg: $ty),*) $(-> $ret)? { inner($($arg),*) }
                #[target_feature(enable = "avx2,fma")]
                fn wide256($($arg: $ty),*) $(-> $ret)? { inner($($arg),*) }
                let fma = std::arch::is_x86_feature_detected!("fma");
                if fma && std::arch::is_x86_feature_detected!("avx512f") {
                    // SAFETY: the CPU supports the enabled features (checked above).
                    return unsafe { wide512($($arg),*) };
                }
                if fma && std::arch::is_x86_feature_detected!("avx2") {
                    // SAFETY: as above.
                    return unsafe { wide256($($arg),*) };
                }
            }
            inner($($arg),*)
        }
    };
}

pub(crate) use multiversion;
