//! The implicit engine's product and regions as the strategies' export reads them
//! ([`StrategySource`], docs/guide.md): the explicit writer, fed from the index space. Each
//! region's ranks are computed when its strategies are written and dropped after, two bytes per
//! product state (four past rank 65 534), asked of a budget first.

use std::cell::RefCell;

use super::moves::Moves;
use super::regions::Regions;
use super::space::Space;
use crate::arena::{ActionId, Owner};
use crate::game::{Belief, States};
use crate::game::{StrategySource, WinRegion};

/// The strategies of a product and its regions, for [`StrategyExport::of`](crate::report::StrategyExport::of).
pub struct Strategies<'a, 'm, M> {
    space: &'a Space<'m, M>,
    regions: &'a Regions,
    /// Asked for the bytes of a region's ranks before they are computed.
    budget: RefCell<Box<dyn FnMut(u64) -> bool + 'a>>,
}

impl<'a, 'm, M: Moves> Strategies<'a, 'm, M> {
    /// The strategies of `space` with its `regions`, asking `budget(bytes)` before a region's
    /// ranks are computed: where it says no, serialising fails.
    pub fn new(
        space: &'a Space<'m, M>,
        regions: &'a Regions,
        budget: impl FnMut(u64) -> bool + 'a,
    ) -> Self {
        Strategies {
            space,
            regions,
            budget: RefCell::new(Box::new(budget)),
        }
    }
}

impl<M: Moves> StrategySource for Strategies<'_, '_, M> {
    fn enumeration(&self) -> States {
        self.space.enumeration()
    }
    fn initial(&self) -> u32 {
        self.space.initial()
    }
    fn for_each_state(&self, f: &mut dyn FnMut(u32)) {
        self.space.for_each_state(f);
    }
    fn owner(&self, h: u32) -> Owner {
        self.space.owner(h)
    }
    fn name(&self, h: u32) -> String {
        self.space.name(h)
    }
    fn edges(&self, h: u32, f: &mut dyn FnMut(ActionId, u32)) {
        self.space.edges(h, f);
    }
    fn action_name(&self, action: ActionId) -> &str {
        &self.space.moves().actions()[action as usize]
    }
    fn belief(&self) -> Belief {
        self.regions.belief()
    }
    fn wins(&self, win: WinRegion, h: u32) -> bool {
        match win {
            WinRegion::Set(set) => self.regions.wins(set, h),
            WinRegion::Believed => self.regions.believed().contains(h as usize),
        }
    }
    fn ranks(&self, win: WinRegion) -> Option<Box<dyn Fn(u32) -> Option<u32> + '_>> {
        let budget = &mut *self.budget.borrow_mut();
        let ranks = self.regions.ranks(self.space, win, budget)?;
        Some(Box::new(move |h| ranks.get(h)))
    }
}
