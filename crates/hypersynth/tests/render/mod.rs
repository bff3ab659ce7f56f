mod font;
mod geometry;
