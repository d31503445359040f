//! One internal logging macro: `defmt` when the `defmt` feature is on,
//! nothing at all otherwise (the arguments are borrowed, not evaluated for
//! output, so a disabled log costs nothing and warns about nothing).

#[cfg(feature = "defmt")]
macro_rules! debug {
    ($($arg:tt)*) => { defmt::debug!($($arg)*) };
}

#[cfg(not(feature = "defmt"))]
macro_rules! debug {
    ($fmt:literal $(, $arg:expr)* $(,)?) => {{
        $( let _ = &$arg; )*
    }};
}

pub(crate) use debug;
