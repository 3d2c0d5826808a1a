// placeholder: replaced by the SH implementation
