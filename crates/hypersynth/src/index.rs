//! Dense 32-bit indices with a type per kind of thing they index.
//!
//! Arena states, product (hypergame) states, MDP states, MDP choices and DFA states are all
//! numbered `0..n` and stored in arrays of 4-byte values. Each kind has its own newtype
//! ([`crate::arena::StateId`], [`crate::game::HState`], [`crate::mdp::MdpState`],
//! [`crate::mdp::ChoiceId`], [`crate::automata::DfaState`]), `#[repr(transparent)]` over `u32`:
//! the same layout and speed as a bare `u32`, but an id of one kind is not accepted where
//! another is expected. Crossing kinds is explicit (`HypergameMdp::node(h)` maps a product state
//! to its MDP state, and back with `product_state`).
//!
//! Every id type implements [`Id`] and has the same inherent helpers: [`Id::new`] from a
//! `usize` (checked), [`Id::index`] to index a slice, [`Id::as_u32`], and `range(n)`, the ids
//! `0..n` in order. `u32` implements [`Id`] too, for untyped numbers kept in dense tables
//! (slots, ranks, levels), so that they follow the same sentinel convention.
//!
//! **Sentinel convention.** `u32::MAX` is never a valid index: a count of ids is at most
//! `u32::MAX` and `Id::new` refuses `u32::MAX` itself. It is [`Id::NONE`], which dense tables
//! store for "no such id / not yet seen / unreachable"; public functions turn it into an
//! `Option` (with [`Id::to_option`]) rather than hand it out.
//!
//! Ids serialise as plain numbers and print (`Display`) as their number.

use std::fmt;
use std::hash::Hash;
use std::iter::FusedIterator;
use std::marker::PhantomData;

/// A dense index of 32 bits (see the module documentation).
pub trait Id: Copy + Eq + Ord + Hash + fmt::Debug {
    /// The sentinel, `u32::MAX`: never a valid index.
    const NONE: Self;

    /// The id with this raw value.
    fn from_u32(raw: u32) -> Self;

    /// The raw value.
    fn as_u32(self) -> u32;

    /// The id of index `index`.
    ///
    /// # Panics
    /// If `index` is `u32::MAX` or more: it would collide with [`Id::NONE`] or not fit.
    #[inline]
    fn new(index: usize) -> Self {
        match Self::try_new(index) {
            Some(id) => id,
            None => panic!("index {index} does not fit a 32-bit id"),
        }
    }

    /// The id of index `index`, `None` if it does not fit below `u32::MAX`.
    #[inline]
    fn try_new(index: usize) -> Option<Self> {
        u32::try_from(index)
            .ok()
            .filter(|&raw| raw != u32::MAX)
            .map(Self::from_u32)
    }

    /// The index, to index a slice with.
    #[inline]
    fn index(self) -> usize {
        self.as_u32() as usize
    }

    /// Whether this is the sentinel [`Id::NONE`].
    #[inline]
    fn is_none(self) -> bool {
        self == Self::NONE
    }

    /// `None` for the sentinel, the id otherwise.
    #[inline]
    fn to_option(self) -> Option<Self> {
        (!self.is_none()).then_some(self)
    }
}

/// Untyped dense numbers (slots, ranks, levels) follow the same convention.
impl Id for u32 {
    const NONE: u32 = u32::MAX;

    #[inline]
    fn from_u32(raw: u32) -> u32 {
        raw
    }

    #[inline]
    fn as_u32(self) -> u32 {
        self
    }
}

/// The ids `start..end` in increasing order (both ends of one kind). An iterator that also knows
/// its bounds, as `Range<u32>` does; ranges of ids cannot be `Range`s because stepping through
/// a `Range<T>` needs an unstable trait.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct IdRange<I> {
    start: u32,
    end: u32,
    kind: PhantomData<I>,
}

impl<I: Id> IdRange<I> {
    /// The ids from `start` (included) to `end` (excluded); empty if `end <= start`.
    #[inline]
    pub fn new(start: I, end: I) -> IdRange<I> {
        IdRange::from_raw(start.as_u32(), end.as_u32())
    }

    /// The ids `0..count`.
    ///
    /// # Panics
    /// If `count` exceeds `u32::MAX`.
    #[inline]
    pub fn up_to(count: usize) -> IdRange<I> {
        match u32::try_from(count) {
            Ok(end) => IdRange::from_raw(0, end),
            Err(_) => panic!("{count} ids do not fit 32-bit indices"),
        }
    }

    #[inline]
    pub(crate) fn from_raw(start: u32, end: u32) -> IdRange<I> {
        IdRange {
            start,
            end: end.max(start),
            kind: PhantomData,
        }
    }

    /// The first id not yet produced (the end when the range is exhausted).
    #[inline]
    pub fn start(&self) -> I {
        I::from_u32(self.start)
    }

    /// The end (excluded).
    #[inline]
    pub fn end(&self) -> I {
        I::from_u32(self.end)
    }

    /// Whether the range has no id left.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.start == self.end
    }

    /// Whether `id` lies in the range (from its current start to its end).
    #[inline]
    pub fn contains(&self, id: I) -> bool {
        (self.start..self.end).contains(&id.as_u32())
    }
}

impl<I: Id> Iterator for IdRange<I> {
    type Item = I;

    #[inline]
    fn next(&mut self) -> Option<I> {
        (self.start < self.end).then(|| {
            self.start += 1;
            I::from_u32(self.start - 1)
        })
    }

    #[inline]
    fn size_hint(&self) -> (usize, Option<usize>) {
        let len = (self.end - self.start) as usize;
        (len, Some(len))
    }
}

impl<I: Id> DoubleEndedIterator for IdRange<I> {
    #[inline]
    fn next_back(&mut self) -> Option<I> {
        (self.start < self.end).then(|| {
            self.end -= 1;
            I::from_u32(self.end)
        })
    }
}

impl<I: Id> ExactSizeIterator for IdRange<I> {}

impl<I: Id> FusedIterator for IdRange<I> {}

/// Defines an id type: `#[repr(transparent)]` over `u32`, with [`Id`], inherent helpers that
/// need no import, `Display` and `Serialize` as the plain number.
macro_rules! id_type {
    ($(#[$attribute:meta])* $visibility:vis struct $name:ident;) => {
        $(#[$attribute])*
        #[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Debug)]
        #[repr(transparent)]
        $visibility struct $name(u32);

        impl $name {
            /// The sentinel (`u32::MAX`, never a valid index): "no such id" in dense tables.
            pub const NONE: $name = $name(u32::MAX);

            /// The id of index `index`; see [`Id::new`](crate::index::Id::new).
            ///
            /// # Panics
            /// If `index` does not fit below `u32::MAX`.
            #[inline]
            pub fn new(index: usize) -> $name {
                <$name as $crate::index::Id>::new(index)
            }

            /// The id of index `index`, `None` if it does not fit below `u32::MAX`.
            #[inline]
            pub fn try_new(index: usize) -> Option<$name> {
                <$name as $crate::index::Id>::try_new(index)
            }

            /// The id with this raw value.
            #[inline]
            pub const fn from_u32(raw: u32) -> $name {
                $name(raw)
            }

            /// The index, to index a slice with.
            #[inline]
            pub const fn index(self) -> usize {
                self.0 as usize
            }

            /// The raw value.
            #[inline]
            pub const fn as_u32(self) -> u32 {
                self.0
            }

            /// Whether this is the sentinel [`Self::NONE`].
            #[inline]
            pub const fn is_none(self) -> bool {
                self.0 == u32::MAX
            }

            /// `None` for the sentinel, the id otherwise.
            #[inline]
            pub const fn to_option(self) -> Option<$name> {
                if self.is_none() { None } else { Some(self) }
            }

            /// The ids `0..count`, in order.
            ///
            /// # Panics
            /// If `count` exceeds `u32::MAX`.
            #[inline]
            pub fn range(count: usize) -> $crate::index::IdRange<$name> {
                $crate::index::IdRange::up_to(count)
            }
        }

        impl $crate::index::Id for $name {
            const NONE: $name = $name::NONE;

            #[inline]
            fn from_u32(raw: u32) -> $name {
                $name(raw)
            }

            #[inline]
            fn as_u32(self) -> u32 {
                self.0
            }
        }

        impl ::std::fmt::Display for $name {
            fn fmt(&self, f: &mut ::std::fmt::Formatter<'_>) -> ::std::fmt::Result {
                ::std::fmt::Display::fmt(&self.0, f)
            }
        }

        impl ::serde::Serialize for $name {
            fn serialize<S: ::serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
                serializer.serialize_u32(self.0)
            }
        }
    };
}

pub(crate) use id_type;

#[cfg(test)]
mod tests {
    use super::*;

    id_type! {
        /// A test id.
        struct TestId;
    }

    #[test]
    fn ids_are_four_bytes_checked_and_print_as_numbers() {
        assert_eq!(std::mem::size_of::<TestId>(), 4);
        assert_eq!(std::mem::size_of::<[TestId; 3]>(), 12);
        let id = TestId::new(7);
        assert_eq!((id.index(), id.as_u32()), (7, 7));
        assert_eq!(id.to_string(), "7");
        assert_eq!(
            serde_json::to_string(&[id, TestId::new(0)]).unwrap(),
            "[7,0]"
        );
        assert_eq!(TestId::try_new(u32::MAX as usize), None);
        assert_eq!(
            TestId::try_new(u32::MAX as usize - 1),
            Some(TestId(u32::MAX - 1))
        );
        assert!(TestId::NONE.is_none() && TestId::NONE.to_option().is_none());
        assert_eq!(TestId::from_u32(3), TestId::new(3));
        assert_eq!(id.to_option(), Some(id));
        assert!(TestId::new(1) < TestId::new(2));
        assert!(std::panic::catch_unwind(|| TestId::new(u32::MAX as usize)).is_err());
    }

    #[test]
    fn ranges_iterate_both_ways_and_know_their_bounds() {
        let all: Vec<TestId> = TestId::range(3).collect();
        assert_eq!(all, [TestId(0), TestId(1), TestId(2)]);
        let mut range = IdRange::new(TestId(2), TestId(5));
        assert_eq!(range.len(), 3);
        assert!(range.contains(TestId(4)) && !range.contains(TestId(5)));
        assert_eq!(range.next_back(), Some(TestId(4)));
        assert_eq!(range.next(), Some(TestId(2)));
        assert_eq!((range.start(), range.end()), (TestId(3), TestId(4)));
        assert!(IdRange::new(TestId(5), TestId(2)).is_empty());
        assert_eq!(IdRange::<u32>::up_to(2).collect::<Vec<_>>(), [0, 1]);
    }
}
