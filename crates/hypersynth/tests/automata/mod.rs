mod hoa;
