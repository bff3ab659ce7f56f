mod engines;
mod robust;
