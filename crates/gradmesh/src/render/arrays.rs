//! Fixed-size arrays built element by element, for the hot loops of every stage.

/// `[f(0), f(1), f(2)]`. Written out: in the hottest loops `array::map` and `array::from_fn`
/// with closures were left as chains of calls (seen with cachegrind).
#[inline(always)]
pub(crate) fn each3<T>(mut f: impl FnMut(usize) -> T) -> [T; 3] {
    [f(0), f(1), f(2)]
}

/// `[f(0), f(1), f(2), f(3)]` (see [`each3`]).
#[inline(always)]
pub(crate) fn each4<T>(mut f: impl FnMut(usize) -> T) -> [T; 4] {
    [f(0), f(1), f(2), f(3)]
}
