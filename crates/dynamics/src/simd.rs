//! Runtime selection of wider vector instructions for the few hot kernels.
//!
//! The workspace builds for baseline x86-64 (SSE2). [`multiversion!`] compiles a kernel a
//! second time with AVX2 (and a third with AVX-512) enabled and picks the widest version the
//! CPU supports, once per call (the feature test is a cached load). Rust never contracts
//! `a*b + c` into a fused multiply-add on its own, and the kernels keep a fixed summation
//! order, so every version returns bit-identical results: the choice affects speed only.

/// Defines `fn $name(args) -> ret` dispatching to AVX-512/AVX2/baseline builds of `$body`.
macro_rules! multiversion {
    ($(#[$meta:meta])* $vis:vis fn $name:ident($($arg:ident : $ty:ty),* $(,)?) $(-> $ret:ty)? $body:block) => {
        $(#[$meta])*
        $vis fn $name($($arg: $ty),*) $(-> $ret)? {
            #[inline(always)]
            fn inner($($arg: $ty),*) $(-> $ret)? $body
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx512f,avx2")]
                fn wide512($($arg: $ty),*) $(-> $ret)? { inner($($arg),*) }
                #[target_feature(enable = "avx2")]
                fn wide256($($arg: $ty),*) $(-> $ret)? { inner($($arg),*) }
                if std::arch::is_x86_feature_detected!("avx512f") {
                    // SAFETY: the CPU supports the enabled features (checked above).
                    return unsafe { wide512($($arg),*) };
                }
                if std::arch::is_x86_feature_detected!("avx2") {
                    // SAFETY: as above.
                    return unsafe { wide256($($arg),*) };
                }
            }
            inner($($arg),*)
        }
    };
}

pub(crate) use multiversion;
